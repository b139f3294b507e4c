// What the lidar-camera workbench shows (the controller's state, ui/lidar_camera/controller.h):
// the snapshot the panels read, with each pair's view, the solve, the meter and a rig's cameras.
// No GL, GLFW or ImGui.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/camera/undistort.h"
#include "core/lidar/cloud.h"
#include "core/lidar/lidar_image.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/rig.h"
#include "core/reproject/reproject.h"
#include "core/session/calibration_job.h"
#include "core/session/pair_record.h"
#include "core/target/board_camera.h"
#include "core/target/lidar_plane.h"
#include "core/targetless/check.h"
#include "ui/state/controller_state.h"
#include "ui/state/shared_pairs.h"
#include "ui/state/view_state.h"

namespace calibench::ui {

// Everything the panels show about one pair: the job's record of it (PairRecord, whole, as the
// job composed it) and the decoded files the views draw. Heavy members are shared, immutable
// buffers; the list of them is one immutable view every snapshot shares (SharedPairs).
struct PairView : PairRecord {
  bool loaded = false;
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const LidarImage> lidar_image;
  std::shared_ptr<const ImageU8> thumbnail;  // small BGR picture of the camera image
  bool awaiting_detection = false;  // loaded, its board to be found once the background allows
};

struct SolverView {
  bool running = false;
  std::vector<IterationReport> iterations;  // recorded by the solver's callback
  std::optional<SolverResult> result;
  std::vector<std::string> solved_pair_ids;  // the pairs behind result->residuals, in order
  // The CLI summary's words on the solve's inputs: the LiDAR model and why, which residuals the
  // pairs gave (DescribeLidarModel, CountResiduals); a reopened session's from its file.
  std::vector<std::string> notes;
  std::string failure;
  // Not a board solve: the targetless check's estimate the user adopted (AdoptCheckEstimate),
  // where it came from in words (SessionResult::targetless_provenance); empty for a solve.
  std::string targetless_provenance;
};

// The targetless check (RunCheck) of a calibration over the scenes of the loaded pairs, as
// `calibench check` runs it (core/targetless): what the check window shows, or why not.
struct CheckView {
  bool running = false;
  std::string checked;  // the calibration checked, in words: a file, or "the workbench's ..."
  std::shared_ptr<const CheckReport> report;
  // Every frame's LiDAR edges by pair id: drawn on that pair's image under R and the estimate.
  std::shared_ptr<const std::map<std::string, std::vector<SceneEdgePoint>>> lidar_edges;
  std::vector<std::string> unreadable;  // frames the check could not read, "file: reason"
  std::string failure;
};

// The camera-side reprojection of the selected pair after a solve.
struct Reprojection {
  std::string pair_id;
  std::vector<ProjectedPoint> points;
  std::vector<bool> visible;
};

// The meter after each solve: σ per camera axis at that many pairs.
struct MeterPoint {
  int pairs = 0;
  Vec3 sigma_t_mm = Vec3::Zero();
  Vec3 sigma_r_deg = Vec3::Zero();
};

// One camera of a rig (core/io/rig_folder.h) as the workbench shows it beside the one open.
struct RigCameraView {
  std::string name;
  CameraModel camera;  // its intrinsics: the 3D view's frustum
  int captures = 0;    // the captures it has a frame of
  // Its own solve (each camera through the pipeline as `calibrate` runs it, with its session's
  // edits); the open camera's is the workbench's latest solve.
  std::shared_ptr<const SolverResult> single;
  int pairs_used = 0;
  std::optional<CaptureState> meter;  // the stop rule on `single` against the goal
  // The rig's joint solve (all cameras in one problem) at its last run; nullopt before one.
  std::optional<Pose> joint_cam_from_lidar;
  std::optional<Pose> single_at_joint;  // its own pose when the rig solve ran (from it)
  Vec3 joint_sigma_t_mm = Vec3::Zero();
  Vec3 joint_sigma_r_deg = Vec3::Zero();
  std::string failure;  // why it has no solve
  // Its frame of the selected capture, small (the strip); null when it has none.
  std::shared_ptr<const ImageU8> frame;
};

// The cameras around the one open: a rig's (Controller::OpenDataset of a rig), or a single
// camera's dataset as a rig of one (RigOfOne). The rig's own solve, its strip and its meter rows
// need several.
struct RigView {
  std::filesystem::path path;  // the rig's folder or manifest
  int active = 0;              // the camera open in the views
  std::vector<RigCameraView> cameras;
  std::string frames_pair;  // the capture the strip's frames show
  bool solving = false;     // the rig solve runs (background steps on the worker)
  std::string progress;     // while solving: the step it is at ("camera cam1 (2 of 3)")
  int shared_captures = 0;  // at the last rig solve: captures two or more cameras saw the board in
  // Each camera after the first relative to the first, from the joint solve (RigRelativePoses).
  std::vector<PoseWithSigmas> relative;
  std::string failure;                                 // the last rig solve's failure
  bool Several() const { return cameras.size() > 1; }  // a rig, not a rig of one
  // Every camera's stop rule is met.
  bool AllDone() const;
  // A camera's own solve moved since the rig solve ran (an edit, a solve): it is out of date.
  bool JointStale() const;
};

struct Snapshot : SnapshotHeader {
  std::filesystem::path dataset_path;
  std::filesystem::path session_path;  // empty: the session lives in memory only (render)
  std::string save_error;  // the last save's failure (autosave, save as); empty once one succeeds
  std::optional<Dataset> dataset;
  // The job's pairs as the views show them: one list shared with the controller's state, which
  // Publish replaces (ui/state/shared_pairs.h); a snapshot copies a pointer.
  SharedPairs<PairView> pairs;
  int selected = -1;
  bool HasPair(int index) const { return index >= 0 && index < static_cast<int>(pairs.size()); }
  std::shared_ptr<const ImageU8> selected_image;  // full-resolution camera image of `selected`
  std::shared_ptr<const UndistortedView> selected_undistorted;  // the same, distortion removed
  // The pair they show (a followed capture's last one until the newest pair's is decoded).
  std::string selected_image_pair;
  SolverView solver;
  std::shared_ptr<const Reprojection> reprojection;
  ViewState view;
  JobSettings settings;  // the job record's (Session::settings)
  bool can_undo = false, can_redo = false;
  int loading_done = 0, loading_total = 0;
  // The camera's intrinsics estimated from the loaded pairs' corners (EstimateIntrinsics), what
  // the intrinsics window shows: coverage, per-image error, σ, the verdict; or why not.
  std::shared_ptr<const IntrinsicsResult> intrinsics;
  std::string intrinsics_failure;
  bool intrinsics_running = false;
  std::filesystem::path intrinsics_saved;  // where SaveIntrinsics last wrote them
  CheckView check;                         // the targetless check window's
  // The meter (core/guidance's stop rule, as `advise` and `watch` judge): σ per direction against
  // the user's goal, the weakest in words, done; its history over the solves.
  CaptureGoal goal;
  double hand_tolerance_m = 0.10;  // the hand's error the next pose is chosen robust to
  double hand_tolerance_deg = 10.0;
  std::optional<CaptureState> meter;
  std::vector<MeterPoint> meter_history;
  // Where to hold the board next (`advise` after every solve): the ghost board in the camera and
  // 3D views, with its words; or why there is none (done, or no feasible pose).
  std::optional<PoseSuggestion> next_pose;
  std::string next_pose_failure;
  // The newest pair against the ghost shown when it was taken (MatchGhost), in words.
  std::string ghost_match;
  bool ghost_matched = false;
  // A folder being followed (WatchFolder): pairs join the list as they land.
  std::filesystem::path watching;
  // A followed recording shows a board no preset explains: why, in words (the board is then
  // picked from a list: PickBoard); empty otherwise.
  std::string board_problem;
  bool auto_solve = false;
  // Opened from a rig: its cameras, the strip of the selected capture's frames, the rig solve.
  std::optional<RigView> rig;
};

// A relative path the user typed (export, save as, a result to check) goes next to the session,
// never into the folder the program was started from.
inline std::filesystem::path NextToSession(const Snapshot& state,
                                           const std::filesystem::path& path) {
  if (path.is_absolute() || state.session_path.empty()) return path;
  return state.session_path.parent_path() / path;
}

}  // namespace calibench::ui
