// What the user asks of the lidar-camera workbench: the intents panels return and the
// controller's Apply carries out (ui/lidar_camera/controller.h), routed to the controller's own
// handlers or to its tasks. No GL, GLFW or ImGui.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/io/camera_file.h"
#include "core/results/export.h"
#include "core/session/calibration_job.h"
#include "ui/state/view_state.h"

namespace calibench::ui {

// What the user asked for. Panels return these; Controller::Apply carries them out.
struct SelectPair {
  int index;
};
struct SetPairStatus {
  int index;
  PairStatus status;
};
struct BrushStroke {
  int index;
  int row;
  int column;
  float radius_px;
  bool erase;
};
struct ClearBrush {
  int index;
};
// The mouse button was released: the brush stroke (BrushStroke / PaintPoints dabs) is complete.
struct EndStroke {};
// Forget the pair's brush (and seed) and detect the board again; every pair when `all`.
struct DetectBoardAgain {
  int index;
  bool all = false;
};
// LiDAR points painted in the 3D view, as the LiDAR-image pixels they landed in (sorted).
struct PaintPoints {
  int index;
  std::vector<int> pixels;
  bool erase;
};
struct RunSolver {};
struct ResetSolver {};
struct SetSettings {  // the solver's settings and the LiDAR plane's RANSAC threshold
  JobSettings settings;
};
struct SetView {
  ViewState view;
};
// The 3D view turned onto the selected pair's board (its cloud before the board is found): the
// F key and the view's "frame" button (ViewTask::Frame).
struct FrameView {};
// Writes the solution: a calibench result (no format), or a file a robot loads in one of the
// export formats, with the frames named (core/results/export.h). A relative path goes next to
// the session.
struct ExportResult {
  std::filesystem::path path;
  std::optional<ExportFormat> format = std::nullopt;
  ExportFrames frames = {};
};
struct SaveSessionAs {
  std::filesystem::path path;
};
struct Undo {};
struct Redo {};
// The user's goal for the meter (σ per axis), and how precisely the person can hold a suggested
// pose (GuidanceOptions::hand_tolerance_*: the next pose is chosen robust to it).
struct SetGoal {
  CaptureGoal goal;
  double hand_tolerance_m = 0.10;
  double hand_tolerance_deg = 10.0;
};
// The camera's intrinsics from every loaded pair's board corners (as `calibench intrinsics`),
// on the worker; the dataset's camera is not changed.
struct EstimateIntrinsics {
  CameraModelType model = CameraModelType::kPinholeRadTan;
};
// Writes the estimated intrinsics as a camera file (a relative path goes beside the dataset).
struct SaveIntrinsics {
  std::filesystem::path path;
  CameraFileFormat format = CameraFileFormat::kRosCameraInfo;
};
// Another camera of the rig into the views (its own session, resumed): the window replaces the
// controller (WindowShell::SelectCamera); a controller alone says so on its status line.
struct SelectCamera {
  std::string camera;
};
// The rig's joint solve over every camera, with each camera's session edits (the open one's as
// they are now), in background steps on the worker; the meter and the frustums follow.
struct SolveRig {};
// A followed recording whose board no preset explains (Snapshot::board_problem): the board the
// user picks, a preset's name (core/board/board.h) or a target file; the pairs held for want of
// it are searched with it.
struct PickBoard {
  std::string board;
};
// The targetless check (core/targetless, the step `calibench check` runs) of a calibration over
// the scenes of the dataset's pairs, on the worker, using no board: `result` a result file or a
// session (relative: beside the session); empty: the workbench's own calibration.
struct RunCheck {
  std::filesystem::path result;
};
// The check's estimate becomes the workbench's calibration, its provenance targetless (an export
// writes a targetless result); one undo step.
struct AdoptCheckEstimate {};
using Intent =
    std::variant<SelectPair, SetPairStatus, BrushStroke, EndStroke, ClearBrush, DetectBoardAgain,
                 PaintPoints, RunSolver, ResetSolver, SetSettings, SetView, FrameView, ExportResult,
                 SaveSessionAs, Undo, Redo, EstimateIntrinsics, SaveIntrinsics, SetGoal,
                 SelectCamera, SolveRig, PickBoard, RunCheck, AdoptCheckEstimate>;

}  // namespace calibench::ui
