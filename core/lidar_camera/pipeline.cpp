#include "core/lidar_camera/pipeline.h"

#include <algorithm>
#include <set>

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar/cloud.h"

namespace calibench {

bool PipelineOptions::Check(std::string* why) const {
  if (!lidar_plane.Check(why) || !detection.Check(why) || !pnp.Check(why) || !solver.Check(why))
    return false;
  if (threads < 1) {
    if (why) *why = "threads must be >= 1";
    return false;
  }
  if (min_pairs < 3) {
    if (why) *why = "min_pairs must be >= 3 (fewer pairs cannot fix six degrees of freedom)";
    return false;
  }
  return true;
}

LidarPlaneOptions LidarPlaneOptionsFor(const PipelineOptions& options, const BoardSpec& target) {
  LidarPlaneOptions lidar = options.lidar_plane;
  if (options.grow_to_board && lidar.grow_radius_m == 0)
    lidar.grow_radius_m = BoardGrowRadius(target);
  // Edges only for a sheet whose size the target states: the pattern's extent is no edge.
  if (target.board_width > 0 && target.board_height > 0 && lidar.sheet_size_m.isZero())
    lidar.sheet_size_m = Vec2(target.board_width, target.board_height);
  return lidar;
}

PlanePair MakePlanePair(const std::string& id, const LidarPlaneFit& lidar,
                        const CameraBoardObservation& camera) {
  return {id,
          lidar.plane,
          camera.plane,
          lidar.covariance,
          camera.plane_covariance,
          lidar.range_offset_jacobian,
          lidar.edge_points,
          camera.cam_from_board,
          0.5 * lidar.sheet_size_m};
}

std::optional<PairInputs> LoadPairInputs(const Dataset& dataset, const PairEntry& pair,
                                         std::string* why) {
  PairInputs inputs;
  try {
    inputs.cloud = LoadCloud(pair.cloud);
    inputs.image = LoadImage(pair.image);
  } catch (const IoError& e) {
    *why = e.what();
    return std::nullopt;
  }
  const CameraModel& camera = dataset.camera;
  if (inputs.image.width != camera.width || inputs.image.height != camera.height) {
    *why = pair.image.string() + ": image is " + std::to_string(inputs.image.width) + "x" +
           std::to_string(inputs.image.height) + " but the camera is " +
           std::to_string(camera.width) + "x" + std::to_string(camera.height);
    return std::nullopt;
  }
  return inputs;
}

CameraFeatures ExtractCameraFeatures(const Dataset& dataset, const ImageU8& image,
                                     const PipelineOptions& options) {
  CameraFeatures features;
  std::string why;
  features.detection = DetectBoard(image, dataset.target, options.detection, &why);
  if (features.detection)
    features.observation =
        EstimateBoardPose(dataset.camera, *features.detection, options.pnp, &why);
  if (!features.observation) features.failure = why;
  return features;
}

std::vector<int> SelectBoardRegion(const LidarCloud& cloud, const BoardHint& hint,
                                   std::string* why) {
  if (hint.brush_pixels && !hint.brush_pixels->empty()) {
    CALIBENCH_CHECK(hint.image != nullptr);
    return SelectBrushRegion(*hint.image, *hint.brush_pixels);
  }
  if (hint.seed) return SelectSeedRegion(cloud, *hint.seed);
  *why = "no board region: brush the board in the workbench or add lidar_seed to the manifest";
  return {};
}

std::optional<LidarPlaneFit> ExtractLidarFeatures(const Dataset& dataset, const LidarCloud& cloud,
                                                  const BoardHint& hint,
                                                  const PipelineOptions& options,
                                                  std::string* why) {
  std::string no_hint;
  const std::vector<int> region = SelectBoardRegion(cloud, hint, &no_hint);
  if (!no_hint.empty()) {
    *why = no_hint;
    return std::nullopt;
  }
  std::string fit_failure;
  auto fit =
      FitBoardPlane(cloud, region, LidarPlaneOptionsFor(options, dataset.target), &fit_failure);
  if (fit) return fit;
  *why = "LiDAR: " + fit_failure;
  const bool from_seed = hint.seed && !(hint.brush_pixels && !hint.brush_pixels->empty());
  if (from_seed)
    *why += " (seed at " + std::to_string(hint.seed->point.norm()).substr(0, 4) + " m, radius " +
            std::to_string(hint.seed->radius).substr(0, 4) + " m)";
  return std::nullopt;
}

void SetStatusFromFeatures(PairFeatures* features, const std::string& lidar_failure,
                           const std::string& camera_failure) {
  const bool usable = features->lidar && features->camera;
  features->status = usable ? PairStatus::kAccepted : PairStatus::kFailed;
  features->reason = usable ? "" : (!features->lidar ? lidar_failure : "camera: " + camera_failure);
}

namespace {

// The region hint for a pair: the user's brush where one was painted (checked against the
// image layout it was painted on), else the manifest's seed. nullopt with *why for a brush that
// does not fit this cloud's image.
std::optional<BoardHint> HintFor(const PairEntry& pair, const PairEdit& edit,
                                 const LidarImage* image, std::string* why) {
  if (!edit.brush_pixels) return BoardHint{.seed = pair.lidar_seed};
  if (image->rows != edit.brush_rows || image->columns != edit.brush_columns) {
    *why = "the brush was painted on a " + std::to_string(edit.brush_rows) + "x" +
           std::to_string(edit.brush_columns) + " LiDAR image but " + pair.cloud.string() +
           " gives " + std::to_string(image->rows) + "x" + std::to_string(image->columns);
    return std::nullopt;
  }
  return BoardHint{&*edit.brush_pixels, image, std::nullopt};
}

}  // namespace

PairFeatures ExtractPairFeatures(const Dataset& dataset, const PairEntry& pair,
                                 const PipelineOptions& options, const PairEdit& edit) {
  PairFeatures features;
  features.id = pair.id;
  std::string why;
  auto inputs = LoadPairInputs(dataset, pair, &why);
  if (!inputs) {
    features.input_error = true;
    SetStatusFromFeatures(&features, why, why);
    return features;
  }
  // The brush's pixels index the image the workbench shows (ProjectById, default options).
  std::optional<LidarImage> image;
  if (edit.brush_pixels) image = ProjectById(inputs->cloud, LidarImageOptions{});
  std::string lidar_failure;
  if (const auto hint = HintFor(pair, edit, image ? &*image : nullptr, &lidar_failure))
    features.lidar = ExtractLidarFeatures(dataset, inputs->cloud, *hint, options, &lidar_failure);
  CameraFeatures camera = ExtractCameraFeatures(dataset, inputs->image, options);
  features.camera = std::move(camera.observation);
  SetStatusFromFeatures(&features, lidar_failure, camera.failure);
  if (edit.rejected) {
    features.status = PairStatus::kRejected;
    features.reason = kRejectedByUser;
  }
  return features;
}

CalibrationOutcome CalibrateDataset(const Dataset& dataset, const PipelineOptions& options,
                                    const ProgressCallback& progress, const PairEdits& edits) {
  std::vector<const PairEntry*> selected;
  const std::set<std::string> wanted(options.pair_ids.begin(), options.pair_ids.end());
  for (const PairEntry& pair : dataset.pairs)
    if (wanted.empty() || wanted.count(pair.id)) selected.push_back(&pair);

  std::vector<PairFeatures> features(selected.size());
  ParallelFor(
      selected.size(), options.threads,
      [&](size_t i) {
        const auto edit = edits.find(selected[i]->id);
        features[i] = ExtractPairFeatures(dataset, *selected[i], options,
                                          edit == edits.end() ? PairEdit{} : edit->second);
      },
      [&](int finished, size_t i) {
        if (progress) progress(finished, static_cast<int>(selected.size()), selected[i]->id);
      });
  return SolveFromFeatures(std::move(features), options);
}

CalibrationOutcome SolveFromFeatures(std::vector<PairFeatures> pairs,
                                     const PipelineOptions& options,
                                     const IterationCallback& on_iteration) {
  CalibrationOutcome outcome;
  outcome.pairs = std::move(pairs);
  std::vector<PlanePair> planes;
  for (PairFeatures& p : outcome.pairs) {
    if (p.status == PairStatus::kPending && p.lidar && p.camera) p.status = PairStatus::kAccepted;
    if (p.status != PairStatus::kAccepted) continue;
    planes.push_back(MakePlanePair(p.id, *p.lidar, *p.camera));
  }
  if (static_cast<int>(planes.size()) < options.min_pairs) {
    outcome.failure = "only " + std::to_string(planes.size()) + " usable pair(s); at least " +
                      std::to_string(options.min_pairs) +
                      " with different board orientations are needed";
    return outcome;
  }
  if (options.initial_cam_from_lidar && options.solver.method != SolverMethod::kKim) {
    outcome.initial_cam_from_lidar = *options.initial_cam_from_lidar;
  } else {
    std::string why;
    const auto guess = InitialGuessFromPlanes(planes, &why);
    if (!guess) {
      outcome.failure = "no initial guess: " + why + " (give one with --initial-guess)";
      return outcome;
    }
    outcome.initial_cam_from_lidar = *guess;
  }
  PlaneAlignmentSolver solver(planes, options.solver, outcome.initial_cam_from_lidar);
  outcome.solution = solver.Run(on_iteration);
  return outcome;
}

void EvaluateAtSolution(const std::vector<PairFeatures>& pairs, const SolverOptions& options,
                        SolverResult* solution) {
  std::vector<PlanePair> planes;
  for (const PairFeatures& p : pairs)
    if (p.status == PairStatus::kAccepted && p.lidar && p.camera)
      planes.push_back(MakePlanePair(p.id, *p.lidar, *p.camera));
  solution->residuals.clear();
  solution->robust_weights.clear();
  if (planes.empty()) return;
  const double offset = solution->range_offset ? solution->range_offset->value_m : 0.0;
  PlaneAlignmentSolver solver(planes, options, solution->cam_from_lidar, offset);
  if (solution->method == options.method && solution->plane_variance_factor > 0 &&
      solution->edge_variance_factor > 0)
    solver.SetVarianceFactors(solution->plane_variance_factor, solution->edge_variance_factor);
  const SolverResult at_estimate = solver.Summarize();
  solution->residuals = at_estimate.residuals;
  solution->robust_weights = at_estimate.robust_weights;
}

}  // namespace calibench
