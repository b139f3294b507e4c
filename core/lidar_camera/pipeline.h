// The headless pipeline over plain data: load -> extract features (planes) -> solve.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/intrinsics/intrinsics.h"
#include "core/io/dataset.h"
#include "core/lidar/cloud.h"
#include "core/lidar/lidar_image.h"
#include "core/lidar/swept_origin.h"
#include "core/lidar_camera/board_track.h"
#include "core/lidar_camera/solver.h"
#include "core/results/pair_status.h"
#include "core/target/board_camera.h"
#include "core/target/lidar_board_detect.h"
#include "core/target/lidar_plane.h"

namespace calibench {

// Which intrinsics --refine-intrinsics estimates (core/lidar_camera/joint_intrinsics.h says why
// the focal length alone is the default).
enum class IntrinsicsToRefine {
  kFocal,    // fx fy
  kPinhole,  // fx fy cx cy
  kAll,      // fx fy cx cy and the distortion (k3 only where the camera uses it)
};

struct PairInputs;  // below

struct PipelineOptions {
  LidarPlaneOptions lidar_plane;
  // The LiDAR's noise model (LidarPlaneOptions::geometry): judged from each cloud
  // (ClassifyLidarGeometry) unless the user forces one (--lidar-model).
  std::optional<LidarGeometry> lidar_model;
  LidarGeometryOptions lidar_geometry;
  // A ring-less cloud's pairs fitted under both candidate models and the one their held-out
  // boards support kept (core/lidar_camera/lidar_model_evidence.h); not with lidar_model.
  LidarModelEvidenceOptions lidar_model_evidence;
  // A swept cloud without viewpoints: where its rays start, estimated from the scan
  // (core/lidar/swept_origin.h), its planes then fitted along them.
  SweptOriginOptions swept_origin;
  BoardDetectionOptions detection;
  PnpOptions pnp;
  SolverOptions solver;
  std::vector<std::string> pair_ids;           // empty = every pair of the dataset
  std::optional<Pose> initial_cam_from_lidar;  // user guess; else the closed form from planes
  int threads = DefaultThreads();              // feature extraction workers
  int min_pairs = 3;                           // planes fix all 6 dof from 3 pairs on
  // LiDAR: grow each brushed / seeded region to the whole board, limited by the target's sheet
  // size (LidarPlaneOptions::grow_radius_m = BoardGrowRadius(target)).
  bool grow_to_board = true;
  // Pairs with neither a brush nor a seed: find the board in the cloud (DetectLidarBoard), with a
  // background model over the selected pairs' clouds (SceneBackground), and check every board
  // against the camera's once a first solution exists (camera-guided completion).
  bool detect_board = true;
  LidarBoardDetectionOptions board_detection;
  bool background_model = true;
  bool camera_guided = true;
  // A LiDAR board whose plane disagrees with the camera's prediction by more than this many
  // standard deviations is not used. The σ of the tilt, in the direction the normals differ, and
  // of the offset: both planes' covariances (the LiDAR's with its rings' range biases,
  // LidarPlaneFit::ring_bias_covariance, so a strip that few rings cross may tilt more about the
  // rings' direction than a full board) and, in quadrature, a floor for what neither model holds
  // (the camera's intrinsics, the sheet's flatness, the beams' footprint): 0.5° and 7.5 mm make
  // 4σ = 2° and 30 mm on a board whose planes' own σ are small.
  double guided_max_sigmas = 4.0;
  double guided_floor_sigma_deg = 0.5;
  double guided_floor_sigma_m = 0.0075;
  // The camera's intrinsics estimated with the extrinsic in one joint problem (corners, LiDAR
  // planes and edges; core/lidar_camera/joint_intrinsics.h), every pair then posed under them.
  bool refine_intrinsics = false;
  IntrinsicsToRefine intrinsics_to_refine = IntrinsicsToRefine::kFocal;
  // The extrinsic's covariance includes the intrinsics' (the camera file's, or the refined
  // camera's), propagated through the solve (AddIntrinsicsUncertainty).
  bool propagate_intrinsics = true;
  // A moving capture's offset between the camera's and the LiDAR's clocks: searched, or given
  // (core/lidar_camera/time_offset.h).
  TimeOffsetOptions time_offset;
  // Sees each pair's files once the extraction has read them, on the extraction's workers (so it
  // must be safe to call from several threads): whoever needs them later (the report's figures)
  // keeps what it needs instead of reading them again. Optional.
  std::function<void(const PairEntry&, const PairInputs&)> on_pair_inputs;
  bool Check(std::string* why) const;
};

// Where a pair's LiDAR board region came from.
enum class BoardSource { kNone, kBrush, kSeed, kDetected, kCameraGuided };
std::string BoardSourceName(BoardSource source);  // "none", "brush", "seed", "detected", ...

// How a pair's LiDAR board was found: the source, a confidence in [0, 1] (1 for a user's brush or
// seed) and, for a detection, what was found.
struct BoardOrigin {
  BoardSource source = BoardSource::kNone;
  double confidence = 0.0;
  std::string detail;
};

struct PairFeatures : PairStanding {
  bool input_error = false;  // the pair's files could not be read
  std::optional<LidarPlaneFit> lidar;
  std::optional<CameraBoardObservation> camera;
  BoardOrigin board_origin;
  std::optional<double> edge_width_px;  // ChessboardEdgeWidthPx of its detection (blur)
  // A moving capture's pair (PairEntry::images): the board in each of its frames that showed
  // it, stamps after the pair's lidar_stamp_ns; `camera` is then the board at the LiDAR's
  // instant under the time offset (PlaceCameraBoardAt). Empty: one image.
  std::vector<TimedObservation> camera_track;
};

// options.lidar_plane for `target`: its grow radius (when options.grow_to_board) and its sheet size
// (for the board edges), where options.lidar_plane leaves them unset.
LidarPlaneOptions LidarPlaneOptionsFor(const PipelineOptions& options, const BoardSpec& target);

// The solver's input for one pair: both planes with their covariances.
PlanePair MakePlanePair(const std::string& id, const LidarPlaneFit& lidar,
                        const CameraBoardObservation& camera);

// The pipeline's steps over one pair, in order: load its files, find the board in the image,
// choose the LiDAR region, fit the LiDAR plane. ExtractPairFeatures runs them all; the workbench
// runs the same functions one at a time (the LiDAR side again after every brush stroke).

// A pair's files as loaded and checked against the camera.
struct PairInputs {
  LidarCloud cloud;
  ImageU8 image;
};
// nullopt with *why naming the file when a file cannot be read or the image is not the camera's
// size. A cloud already read (`preloaded`, e.g. by BuildSceneBackground) is moved in instead of
// being read again.
std::optional<PairInputs> LoadPairInputs(const Dataset& dataset, const PairEntry& pair,
                                         std::string* why, LidarCloud* preloaded = nullptr);

// The camera side: the board detected in the image and its plane by PnP; `failure` says why
// `observation` is absent. `detection` is kept even when PnP fails.
struct CameraFeatures {
  std::optional<BoardDetection> detection;
  std::optional<CameraBoardObservation> observation;
  std::string failure;
  std::optional<double> edge_width_px;  // ChessboardEdgeWidthPx (checkerboards)
};
CameraFeatures ExtractCameraFeatures(const Dataset& dataset, const ImageU8& image,
                                     const PipelineOptions& options);

// Where the user said the board is. A brush (LiDAR-image pixels on `image`) replaces the seed;
// without a brush the seed's cone of rays is used (SelectSeedRegion). The one place that decides
// which LiDAR points a plane is fitted to, for the CLI and the workbench alike.
struct BoardHint {
  // Owned, not pointed to: a hint built from a PairEdit returned by value (the job's EditOf)
  // must not outlive the edit's pixels (issue 51's use-after-free). Empty: no brush.
  std::vector<int> brush_pixels;
  const LidarImage* image = nullptr;  // the image the brush was painted on
  std::optional<LidarSeed> seed;
  bool seed_from_camera = false;  // the seed is the camera's prediction
  // The camera's prediction of the board's plane (LiDAR frame): only the seed's returns within
  // this band of it are candidates, so that a sparse cloud's few board returns are not outvoted
  // by what lies behind the sheet. nullopt: the seed's cone alone.
  std::optional<Plane> predicted_plane;
  double predicted_band_m = 0.10;
  bool detect = true;  // without brush or seed: detect the board (false: the user erased it)
  const SceneBackground* background = nullptr;  // for detection; may be null
};
// Candidate points (indices into the cloud); empty with *why when there is no hint.
std::vector<int> SelectBoardRegion(const LidarCloud& cloud, const BoardHint& hint,
                                   std::string* why);

// The LiDAR side: the board plane fitted to the hint's region (SelectBoardRegion) or, without a
// hint, to the board detected in the cloud (options.detect_board), grown to the sheet
// (LidarPlaneOptionsFor). nullopt with *why ("LiDAR: ...", or the missing hint) when no plane is
// found. *origin (optional) says where the region came from.
std::optional<LidarPlaneFit> ExtractLidarFeatures(const Dataset& dataset, const LidarCloud& cloud,
                                                  const BoardHint& hint,
                                                  const PipelineOptions& options, std::string* why,
                                                  BoardOrigin* origin = nullptr);

// The status of a pair from its two sides: kAccepted with both planes, else kFailed with the
// first missing side's failure (LiDAR first; the camera's prefixed "camera: ").
void SetStatusFromFeatures(PairFeatures* features, const std::string& lidar_failure,
                           const std::string& camera_failure);

// What the workbench's user decided for a pair, as a session keeps it (core/session turns a
// session into these): a painted brush replaces the manifest's seed, a rejection keeps the pair
// out of the solve.
struct PairEdit {
  // LiDAR-image pixels (ProjectById with default LidarImageOptions) painted by the user; absent =
  // the manifest's seed. Present but empty = the user erased the board.
  std::optional<std::vector<int>> brush_pixels;
  int brush_rows = 0;  // the image layout the brush was painted on
  int brush_columns = 0;
  bool rejected = false;

  bool operator==(const PairEdit&) const = default;
};
using PairEdits = std::map<std::string, PairEdit>;  // by pair id

// The hint for a pair as the user left it (`edit`): a painted brush (checked against the
// image layout it was painted on), else the manifest's seed, else detection. nullopt with *why
// for a brush that does not fit this cloud's image. The one rule of `calibrate`, `watch` and the
// workbench (whose "detect again" passes the pair without its seed).
std::optional<BoardHint> BoardHintFor(const PairEntry& pair, const PairEdit& edit,
                                      const LidarImage* image, std::string* why);

// What --refine-intrinsics did: the camera before and after (with the refined parameters'
// covariance), how the joint problem went, or why it could not run.
struct IntrinsicsRefinement {
  CameraModel before, after;
  std::vector<bool> refined;  // per IntrinsicParameters entry: estimated (false: held fixed)
  Pose joint_cam_from_lidar = Pose::Identity();  // the joint problem's own extrinsic
  double corner_rms_px = 0.0;
  double corner_sigma_px = 0.0;
  double plane_variance_factor = 1.0;
  int pairs = 0, corners = 0, edge_points = 0;
  int iterations = 0;
  bool converged = false;
  std::string failure;  // why the refinement did not run ("" when it did)
};

struct CalibrationOutcome {
  std::vector<PairFeatures> pairs;
  std::optional<SolverResult> solution;  // absent when no calibration could be computed
  std::string failure;                   // why `solution` is absent
  Pose initial_cam_from_lidar = Pose::Identity();
  std::string background_note;  // why no background model was used, when one was wanted
  std::optional<IntrinsicsRefinement> intrinsics_refinement;  // PipelineOptions::refine_intrinsics
  // The camera's intrinsics as estimated from the pairs' images before the calibration
  // (`calibrate --estimate-intrinsics`), for the result file to say so; absent when a camera
  // file gave them.
  std::optional<IntrinsicsResult> estimated_intrinsics;
  // How the data chose a ring-less LiDAR's noise model (ChooseLidarModelByEvidence); absent when
  // they were not asked (rings, a forced model, too few pairs).
  std::optional<LidarModelEvidence> lidar_model_evidence;
  // The camera's clock against the LiDAR's (EstimateTimeOffset): estimated from a moving
  // capture, given, or why not.
  TimeOffsetEstimate time_offset;
};
// The outcome's pairs accepted for the solve.
int AcceptedPairs(const CalibrationOutcome& outcome);

// The boards of a moving capture's frames, each frame read and posed once however many pairs
// list it (thread-safe: one per extraction of a dataset).
class FrameBoards {
 public:
  FrameBoards() = default;
  // A copy (of a job, say) keeps what was posed, with a lock of its own.
  FrameBoards(const FrameBoards& other) : seen_(other.Copy()) {}
  FrameBoards& operator=(const FrameBoards& other) {
    auto seen = other.Copy();
    std::lock_guard lock(mutex_);
    seen_ = std::move(seen);
    return *this;
  }
  // The board in `image` (nullopt: unreadable, not the camera's size, or no board in it).
  std::optional<CameraBoardObservation> Of(const Dataset& dataset,
                                           const std::filesystem::path& image,
                                           const PipelineOptions& options);
  // The whole camera side of `image` (ExtractCameraFeatures), searched once: a pair's own image
  // is one of its frames, and often another pair's. `decoded`: its pixels, already read.
  CameraFeatures Features(const Dataset& dataset, const std::filesystem::path& image,
                          const PipelineOptions& options, const ImageU8* decoded);

 private:
  using Boards = std::map<std::filesystem::path, CameraFeatures>;
  Boards Copy() const {
    std::lock_guard lock(mutex_);
    return seen_;
  }
  mutable std::mutex mutex_;
  Boards seen_;
};

// The same view of a checkerboard in its other corner order: the board frame turned 180 degrees
// about its normal (the origin is the pattern's centre). Pixels stay; each corner's board point
// and id become its opposite's, and the pose's covariance (right perturbation) follows the turn.
void TurnCheckerboardObservation(const BoardSpec& board, CameraBoardObservation* observation);

// A moving capture's frames (PairEntry::images): the board in each that shows it, stamps after
// the pair's lidar_stamp_ns (seconds); a frame that cannot be read or shows no board leaves a gap.
// `frames` (optional) poses each frame once across the pairs that list it.
std::vector<TimedObservation> TrackBoard(const Dataset& dataset, const PairEntry& pair,
                                         const PipelineOptions& options,
                                         FrameBoards* frames = nullptr);

// Loads the pair's files and extracts both planes (the steps above; the hint is the pair's edited
// brush, else its seed). Never throws for bad data: the pair comes back kFailed with the reason
// (unreadable files name the file); a rejected pair comes back kRejected with its features.
PairFeatures ExtractPairFeatures(const Dataset& dataset, const PairEntry& pair,
                                 const PipelineOptions& options, const PairEdit& edit = {},
                                 const SceneBackground* background = nullptr,
                                 LidarCloud* preloaded_cloud = nullptr,
                                 FrameBoards* frames = nullptr);

// The background model over the selected pairs' clouds (for detection); nullopt with *why when it
// cannot be built (fewer than 3 readable clouds, or they repeat no static scene). `clouds`
// (optional) receives the clouds it read, per pair (nullopt where unreadable), so that the
// extraction does not read them again.
std::optional<SceneBackground> BuildSceneBackground(
    const std::vector<const PairEntry*>& pairs, int threads, std::string* why,
    std::vector<std::optional<LidarCloud>>* clouds = nullptr);

// A result nothing supports is refused (`solution` reset, `failure` saying why) when fewer than
// options.min_pairs accepted pairs keep a robust weight above the negligible one (the rest were
// down-weighted to nothing). One whose standard deviation exceeds what the boards can tell (the
// sheet's diagonal in translation, the angle the sheet spans at the pairs' mean distance in
// rotation) is kept but never "well constrained": the observability says why. The last step of
// SolveExtractedPairs, so `calibrate`, `watch` and the workbench judge alike.
void JudgeSolutionSupport(const BoardSpec& board, const PipelineOptions& options,
                          CalibrationOutcome* outcome);

// Camera-guided completion (options.camera_guided): with a first solution, predicts every pair's
// board in the LiDAR frame from its camera pose, drops LiDAR boards that disagree with it (the
// pair fails, saying by how much) and looks again for the board at the prediction where the LiDAR
// side failed or disagreed; re-solves until no pair changes (at most 3 rounds). Pairs with a brush
// are the user's word and are left alone.
void CompleteWithCamera(const Dataset& dataset, const std::vector<const PairEntry*>& pairs,
                        const PipelineOptions& options, const PairEdits& edits,
                        CalibrationOutcome* outcome);

// Why a pair's LiDAR board disagrees with where its camera board puts it under cam_from_lidar
// (the gate of CompleteWithCamera: options.guided_max_sigmas of both planes' σ with the floors
// guided_floor_sigma_deg and guided_floor_sigma_m), or "" when they agree.
std::string BoardDisagreement(const LidarPlaneFit& lidar, const CameraBoardObservation& camera,
                              const Pose& cam_from_lidar, const BoardSpec& target,
                              const PipelineOptions& options);

using IterationCallback = std::function<void(const IterationReport&)>;

// The steps after extraction, as `calibrate`, `watch` and the workbench all run them: the solve
// (SolveFromFeatures, on_iteration watching it), camera-guided completion (options.camera_guided;
// `pairs` are the entries behind `features`, index by index), then the intrinsics
// (RefineIntrinsics with options.refine_intrinsics and `camera`, else AddIntrinsicsUncertainty).
CalibrationOutcome SolveExtractedPairs(const Dataset& dataset,
                                       const std::vector<const PairEntry*>& pairs,
                                       std::vector<PairFeatures> features,
                                       const PipelineOptions& options, const PairEdits& edits = {},
                                       const IterationCallback& on_iteration = {});

// The dataset's pairs that options.pair_ids selects (every pair when it is empty), in order.
std::vector<const PairEntry*> SelectedPairs(const Dataset& dataset, const PipelineOptions& options);

// Extracts the selected pairs as `calibrate` does: the background model over all their clouds
// first (where a pair is left to detection), then every pair's planes in parallel
// (options.threads), `progress` after each. *background_note says why no background model was
// used, when one was wanted.
std::vector<PairFeatures> ExtractDatasetPairs(const Dataset& dataset,
                                              const std::vector<const PairEntry*>& selected,
                                              const PipelineOptions& options,
                                              const ProgressCallback& progress,
                                              const PairEdits& edits, std::string* background_note);

// Extracts every selected pair (in parallel with options.threads) and solves; with
// options.refine_intrinsics refines the camera with the extrinsic (RefineIntrinsics), else adds the
// camera's intrinsics covariance, when it has one, to the extrinsic's (AddIntrinsicsUncertainty).
CalibrationOutcome CalibrateDataset(const Dataset& dataset, const PipelineOptions& options,
                                    const ProgressCallback& progress = {},
                                    const PairEdits& edits = {});

// Solves from already extracted features; pairs not kAccepted are ignored. Pairs with a
// (lidar, camera) plane and status kPending count as accepted. on_iteration (optional) sees every
// Gauss-Newton iteration as it happens (the workbench's live cost plot).
CalibrationOutcome SolveFromFeatures(std::vector<PairFeatures> pairs,
                                     const PipelineOptions& options,
                                     const IterationCallback& on_iteration = {});

// The solver's residuals and robust weights at `solution` for the accepted pairs (in order),
// weighed as that solve weighed them (its variance factors, when its method is options.solver's).
// What the workbench shows after a status change, and what an exported result lists.
void EvaluateAtSolution(const std::vector<PairFeatures>& pairs, const SolverOptions& options,
                        SolverResult* solution);

}  // namespace calibench
