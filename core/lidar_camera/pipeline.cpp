#include "core/lidar_camera/pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/base/image.h"
#include "core/base/names.h"
#include "core/base/parallel.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar/cloud.h"
#include "core/lidar_camera/joint_intrinsics.h"
#include "core/lidar_camera/lidar_model_evidence.h"
#include "core/lidar_camera/time_offset.h"

namespace calibench {

bool PipelineOptions::Check(std::string* why) const {
  if (!lidar_plane.Check(why) || !detection.Check(why) || !pnp.Check(why) || !solver.Check(why) ||
      !board_detection.Check(why) || !lidar_geometry.Check(why) || !swept_origin.Check(why) ||
      !lidar_model_evidence.Check(why) || !time_offset.Check(why))
    return false;
  if (!(guided_max_sigmas > 0 && guided_floor_sigma_deg >= 0 && guided_floor_sigma_m >= 0)) {
    if (why) *why = "guided_max_sigmas must be > 0 and the guided floors >= 0";
    return false;
  }
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

namespace {
constexpr EnumName<BoardSource> kBoardSourceNames[] = {
    {BoardSource::kNone, "none"},
    {BoardSource::kBrush, "brush"},
    {BoardSource::kSeed, "seed"},
    {BoardSource::kDetected, "detected"},
    {BoardSource::kCameraGuided, "camera-guided"}};
}  // namespace

std::string BoardSourceName(BoardSource source) { return NameIn(kBoardSourceNames, source); }

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
  return {id, lidar.plane, camera.plane,
          // A ring-less crop's ring biases found in its elevations (whatever model fits it); a
          // spinning scan's rings enter the solve through their edges and the gate instead.
          lidar.lidar_model.geometry != LidarGeometry::kSpinning
              ? Mat4(lidar.covariance + lidar.ring_bias_covariance)
              : lidar.covariance,
          camera.plane_covariance, lidar.range_offset_jacobian, lidar.edge_points,
          camera.cam_from_board, 0.5 * lidar.sheet_size_m, camera.pose_covariance};
}

std::optional<PairInputs> LoadPairInputs(const Dataset& dataset, const PairEntry& pair,
                                         std::string* why, LidarCloud* preloaded) {
  PairInputs inputs;
  try {
    inputs.cloud = preloaded ? std::move(*preloaded) : LoadCloud(pair.cloud);
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
  if (features.detection) {
    features.observation =
        EstimateBoardPose(dataset.camera, *features.detection, options.pnp, &why);
    features.edge_width_px = ChessboardEdgeWidthPx(image, dataset.target, *features.detection);
  }
  if (!features.observation) features.failure = why;
  return features;
}

std::vector<int> SelectBoardRegion(const LidarCloud& cloud, const BoardHint& hint,
                                   std::string* why) {
  if (!hint.brush_pixels.empty()) {
    CALIBENCH_CHECK(hint.image != nullptr);
    return SelectBrushRegion(*hint.image, hint.brush_pixels);
  }
  if (hint.seed && hint.predicted_plane) {
    std::vector<int> near_plane;
    for (int i : SelectSeedRegion(cloud, *hint.seed))
      if (std::abs(hint.predicted_plane->SignedDistance(cloud.points[i].cast<double>())) <=
          hint.predicted_band_m)
        near_plane.push_back(i);
    return near_plane;
  }
  if (hint.seed) return SelectSeedRegion(cloud, *hint.seed);
  *why = "no board region: brush the board in the workbench or add lidar_seed to the manifest";
  return {};
}

namespace {

// The region of the hint (brush, else seed) or, without one, of the detected board.
std::vector<int> RegionFor(const Dataset& dataset, const LidarCloud& cloud, const BoardHint& hint,
                           const PipelineOptions& options, std::string* why, BoardOrigin* origin) {
  const bool brushed = !hint.brush_pixels.empty();
  if (brushed || hint.seed || !options.detect_board || !hint.detect) {
    *origin = {brushed                 ? BoardSource::kBrush
               : hint.seed_from_camera ? BoardSource::kCameraGuided
               : hint.seed             ? BoardSource::kSeed
                                       : BoardSource::kNone,
               1.0, ""};
    return SelectBoardRegion(cloud, hint, why);
  }
  const LidarBoardDetection found =
      DetectLidarBoard(cloud, dataset.target, options.board_detection, hint.background);
  if (!found.board) {
    *why = "LiDAR: " + found.reason;
    *origin = {BoardSource::kDetected, 0.0, found.reason};
    return {};
  }
  *origin = {BoardSource::kDetected, found.confidence, found.board->Describe(dataset.target)};
  return found.board->indices;
}

}  // namespace

std::optional<LidarPlaneFit> ExtractLidarFeatures(const Dataset& dataset, const LidarCloud& cloud,
                                                  const BoardHint& hint,
                                                  const PipelineOptions& options, std::string* why,
                                                  BoardOrigin* origin) {
  BoardOrigin found;
  std::string no_region;
  const std::vector<int> region = RegionFor(dataset, cloud, hint, options, &no_region, &found);
  if (origin) *origin = found;
  if (!no_region.empty()) {
    *why = no_region;
    return std::nullopt;
  }
  std::string fit_failure;
  LidarPlaneOptions plane_options = LidarPlaneOptionsFor(options, dataset.target);
  LidarGeometryVerdict model;
  if (options.lidar_model)
    model = {*options.lidar_model, "chosen by the user (--lidar-model)", true};
  else
    model = ClassifyLidarGeometry(cloud, options.lidar_geometry);
  plane_options.geometry = model.geometry;
  plane_options.board_only_crop = model.geometry == LidarGeometry::kSegment;
  // A swept scan's rays start on a mirror the stage turns: where the cloud does not say, the
  // estimate from the scan gives each return its ray (never the origin, assumed).
  std::optional<LidarCloud> with_rays;
  if (model.geometry == LidarGeometry::kSwept && !cloud.HasViewpoint()) {
    if (const std::optional<SweptOrigin> mirror =
            EstimateSweptOrigin(cloud, options.swept_origin)) {
      with_rays = cloud;
      with_rays->viewpoint = SweptViewpoints(cloud, *mirror);
      model.why += "; " + DescribeSweptOrigin(*mirror);
    } else {
      model.why += "; where its rays start could not be told from the scan: fitted point-to-plane";
    }
  }
  auto fit = FitBoardPlane(with_rays ? *with_rays : cloud, region, plane_options, &fit_failure);
  if (fit) {
    fit->lidar_model = model;
    // A ring-less cloud's look cannot say how its rays run: the other candidate model's fit of
    // the same region too, for the data to choose between (ChooseLidarModelByEvidence).
    if (!options.lidar_model && !cloud.HasRing() && options.lidar_model_evidence.enabled) {
      const bool along_rays = RaysFromOrigin(model.geometry) || fit->range_moments.count > 0;
      LidarPlaneOptions other = plane_options;
      other.geometry = along_rays ? LidarGeometry::kSegment : LidarGeometry::kNonRepetitive;
      std::string other_failure;
      if (auto alternative = FitBoardPlane(cloud, region, other, &other_failure)) {
        // Said only where the held-out pairs choose it over the cloud's look.
        alternative->lidar_model = {other.geometry, kChosenByHeldOutPairs + model.why, false};
        fit->alternative = std::make_shared<const LidarPlaneFit>(std::move(*alternative));
      }
    }
    return fit;
  }
  *why = "LiDAR: " + fit_failure;
  if (found.source == BoardSource::kSeed || found.source == BoardSource::kCameraGuided)
    *why += std::string(found.source == BoardSource::kSeed ? " (seed" : " (camera's prediction") +
            " at " + std::to_string(hint.seed->point.norm()).substr(0, 4) + " m, radius " +
            std::to_string(hint.seed->radius).substr(0, 4) + " m)";
  else if (found.source == BoardSource::kDetected)
    *why += " (detected " + found.detail + ")";
  return std::nullopt;
}

void SetStatusFromFeatures(PairFeatures* features, const std::string& lidar_failure,
                           const std::string& camera_failure) {
  const bool usable = features->lidar && features->camera;
  features->status = usable ? PairStatus::kAccepted : PairStatus::kFailed;
  features->reason = usable ? "" : (!features->lidar ? lidar_failure : "camera: " + camera_failure);
}

std::optional<BoardHint> BoardHintFor(const PairEntry& pair, const PairEdit& edit,
                                      const LidarImage* image, std::string* why) {
  if (!edit.brush_pixels) {
    BoardHint hint;
    hint.seed = pair.lidar_seed;
    return hint;
  }
  if (image->rows != edit.brush_rows || image->columns != edit.brush_columns) {
    *why = "the brush was painted on a " + std::to_string(edit.brush_rows) + "x" +
           std::to_string(edit.brush_columns) + " LiDAR image but " + pair.cloud.string() +
           " gives " + std::to_string(image->rows) + "x" + std::to_string(image->columns);
    return std::nullopt;
  }
  BoardHint hint;
  hint.brush_pixels = *edit.brush_pixels;
  hint.image = image;
  hint.detect = false;  // the user's brush, even an erased one, is the word
  return hint;
}

PairFeatures ExtractPairFeatures(const Dataset& dataset, const PairEntry& pair,
                                 const PipelineOptions& options, const PairEdit& edit,
                                 const SceneBackground* background, LidarCloud* preloaded_cloud,
                                 FrameBoards* frames) {
  PairFeatures features;
  features.id = pair.id;
  std::string why;
  auto inputs = LoadPairInputs(dataset, pair, &why, preloaded_cloud);
  if (!inputs) {
    features.input_error = true;
    SetStatusFromFeatures(&features, why, why);
    return features;
  }
  if (options.on_pair_inputs) options.on_pair_inputs(pair, *inputs);
  // The brush's pixels index the image the workbench shows (ProjectById, default options).
  std::optional<LidarImage> image;
  if (edit.brush_pixels) image = ProjectById(inputs->cloud, LidarImageOptions{});
  std::string lidar_failure;
  if (auto hint = BoardHintFor(pair, edit, image ? &*image : nullptr, &lidar_failure)) {
    hint->background = background;
    features.lidar = ExtractLidarFeatures(dataset, inputs->cloud, *hint, options, &lidar_failure,
                                          &features.board_origin);
  }
  // A moving capture's image is one of its frames: searched once for the pair and its track.
  CameraFeatures camera = frames && !pair.images.empty()
                              ? frames->Features(dataset, pair.image, options, &inputs->image)
                              : ExtractCameraFeatures(dataset, inputs->image, options);
  features.camera = std::move(camera.observation);
  features.edge_width_px = camera.edge_width_px;
  if (!pair.images.empty()) features.camera_track = TrackBoard(dataset, pair, options, frames);
  SetStatusFromFeatures(&features, lidar_failure, camera.failure);
  if (edit.rejected) {
    features.status = PairStatus::kRejected;
    features.reason = kRejectedByUser;
  }
  return features;
}

std::optional<SceneBackground> BuildSceneBackground(const std::vector<const PairEntry*>& pairs,
                                                    int threads, std::string* why,
                                                    std::vector<std::optional<LidarCloud>>* kept) {
  std::vector<std::optional<LidarCloud>> clouds(pairs.size());
  ParallelFor(pairs.size(), threads, [&](size_t i) {
    try {
      clouds[i] = LoadCloud(pairs[i]->cloud);
    } catch (const IoError&) {  // the pair itself reports it when it is extracted
    }
  });
  SceneBackground background;
  for (const auto& cloud : clouds)
    if (cloud) background.Add(*cloud);
  if (kept) *kept = std::move(clouds);
  if (!background.Finish(why)) return std::nullopt;
  return background;
}

std::vector<const PairEntry*> SelectedPairs(const Dataset& dataset,
                                            const PipelineOptions& options) {
  std::vector<const PairEntry*> selected;
  const std::set<std::string> wanted(options.pair_ids.begin(), options.pair_ids.end());
  for (const PairEntry& pair : dataset.pairs)
    if (wanted.empty() || wanted.count(pair.id)) selected.push_back(&pair);
  return selected;
}

CalibrationOutcome SolveExtractedPairs(const Dataset& dataset,
                                       const std::vector<const PairEntry*>& pairs,
                                       std::vector<PairFeatures> features,
                                       const PipelineOptions& options, const PairEdits& edits,
                                       const IterationCallback& on_iteration) {
  CalibrationOutcome outcome = SolveFromFeatures(std::move(features), options, on_iteration);
  if (options.camera_guided) CompleteWithCamera(dataset, pairs, options, edits, &outcome);
  if (outcome.solution && options.refine_intrinsics)
    RefineIntrinsics(dataset.camera, options, &outcome);
  else if (outcome.solution && options.propagate_intrinsics)
    AddIntrinsicsUncertainty(outcome.pairs, dataset.camera, options, &*outcome.solution);
  JudgeSolutionSupport(dataset.target, options, &outcome);
  return outcome;
}

void JudgeSolutionSupport(const BoardSpec& board, const PipelineOptions& options,
                          CalibrationOutcome* outcome) {
  if (!outcome->solution) return;
  const SolverResult& solution = *outcome->solution;
  int accepted = 0, supporting = 0;
  double distance_sum = 0.0;
  for (const PairFeatures& p : outcome->pairs) {
    if (p.status != PairStatus::kAccepted || !p.lidar || !p.camera) continue;
    if (!solution.DownWeighted(accepted)) {
      ++supporting;
      distance_sum += std::abs(p.camera->plane.distance);
    }
    ++accepted;
  }
  char text[400];
  if (supporting < options.min_pairs && supporting == accepted) {
    std::snprintf(text, sizeof(text),
                  "only %d pair(s) were left accepted; at least %d with different "
                  "board orientations are needed",
                  accepted, options.min_pairs);
    outcome->failure = text;
    outcome->solution.reset();
    return;
  }
  if (supporting < options.min_pairs) {
    std::snprintf(text, sizeof(text),
                  "%d of the %d accepted pairs were down-weighted to nothing (their "
                  "planes disagree with any one pose beyond the noise model), so only %d support "
                  "the result and at least %d must; check the LiDAR model (--lidar-model) and the "
                  "pairs' LiDAR planes",
                  accepted - supporting, accepted, supporting, options.min_pairs);
    outcome->failure = text;
    outcome->solution.reset();
    return;
  }
  // What the boards themselves can tell: an offset known no better than the sheet's diagonal, or a
  // rotation no better than the angle the sheet spans at the boards' mean distance, says nothing
  // about where the sensors are.
  const double diagonal_m = std::hypot(board.SheetWidth(), board.SheetHeight());
  if (diagonal_m <= 0.0) return;
  const Vec6 sigma = solution.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  const double sigma_translation_m = sigma.head<3>().maxCoeff();
  const double sigma_rotation_rad = sigma.tail<3>().maxCoeff();
  const double span_rad = std::atan2(diagonal_m, distance_sum / supporting);
  if (sigma_translation_m <= diagonal_m && sigma_rotation_rad <= span_rad) return;
  std::snprintf(text, sizeof(text),
                "the result's standard deviation (%.3f m, %.2f deg) exceeds what the boards can "
                "tell (the sheet's diagonal %.3f m, the %.2f deg it spans at %.2f m): more pairs, "
                "at more orientations, would constrain it",
                sigma_translation_m, sigma_rotation_rad * 180.0 / M_PI, diagonal_m,
                span_rad * 180.0 / M_PI, distance_sum / supporting);
  outcome->solution->observability.well_constrained = false;
  outcome->solution->observability.weak_directions.push_back(text);
}

CalibrationOutcome SolveFromFeatures(std::vector<PairFeatures> pairs,
                                     const PipelineOptions& options,
                                     const IterationCallback& on_iteration) {
  CalibrationOutcome outcome;
  outcome.pairs = std::move(pairs);
  std::vector<PlanePair> planes;
  for (PairFeatures& p : outcome.pairs) {
    if (p.status == PairStatus::kPending && p.lidar && p.camera) p.status = PairStatus::kAccepted;
  }
  // A ring-less LiDAR's model, as its pairs' held-out boards choose it.
  if (options.lidar_model_evidence.enabled)
    outcome.lidar_model_evidence =
        ChooseLidarModelByEvidence(&outcome.pairs, options, options.lidar_model_evidence);
  PlaceBoardsInTime(options, &outcome);
  for (const PairFeatures& p : outcome.pairs) {
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
  // The offset's own uncertainty moves the pose along how the pose follows it.
  const TimeOffsetEstimate& offset = outcome.time_offset;
  if (offset.camera_minus_lidar_s && !offset.fixed)
    outcome.solution->covariance +=
        offset.std_s * offset.std_s * offset.pose_rate * offset.pose_rate.transpose();
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
  solution->negligible_weight = options.negligible_weight;
}

int AcceptedPairs(const CalibrationOutcome& outcome) {
  return static_cast<int>(
      std::count_if(outcome.pairs.begin(), outcome.pairs.end(),
                    [](const PairFeatures& p) { return p.status == PairStatus::kAccepted; }));
}

}  // namespace calibench
