#include "core/pipeline.h"

#include <algorithm>
#include <set>

#include "core/cloud.h"
#include "core/image.h"
#include "core/parallel.h"

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

std::string PairStatusName(PairStatus status) {
  switch (status) {
    case PairStatus::kPending:
      return "pending";
    case PairStatus::kAccepted:
      return "accepted";
    case PairStatus::kRejected:
      return "rejected";
    case PairStatus::kFailed:
      return "failed";
  }
  return "unknown";
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

PairFeatures ExtractPairFeatures(const Dataset& dataset, const PairEntry& pair,
                                 const PipelineOptions& options) {
  PairFeatures features;
  features.id = pair.id;
  auto fail = [&](const std::string& reason) {
    features.status = PairStatus::kFailed;
    features.reason = reason;
    return features;
  };
  LidarCloud cloud;
  ImageU8 image;
  try {
    cloud = LoadCloud(pair.cloud);
    image = LoadImage(pair.image);
  } catch (const IoError& e) {
    features.input_error = true;
    return fail(e.what());
  }
  if (image.width != dataset.camera.width || image.height != dataset.camera.height)
    return fail(pair.image.string() + ": image is " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " but the camera is " +
                std::to_string(dataset.camera.width) + "x" + std::to_string(dataset.camera.height));

  if (!pair.lidar_seed)
    return fail(
        "no lidar_seed for this pair: brush the board in the workbench or add lidar_seed "
        "to the manifest");
  const std::vector<int> region = SelectSeedRegion(cloud, *pair.lidar_seed);
  std::string why;
  features.lidar =
      FitBoardPlane(cloud, region, LidarPlaneOptionsFor(options, dataset.target), &why);
  if (!features.lidar)
    return fail("LiDAR: " + why + " (seed at " +
                std::to_string(pair.lidar_seed->point.norm()).substr(0, 4) + " m, radius " +
                std::to_string(pair.lidar_seed->radius).substr(0, 4) + " m)");

  const auto detection = DetectBoard(image, dataset.target, options.detection, &why);
  if (!detection) return fail("camera: " + why);
  features.camera = EstimateBoardPose(dataset.camera, *detection, options.pnp, &why);
  if (!features.camera) return fail("camera: " + why);
  features.status = PairStatus::kAccepted;
  return features;
}

CalibrationOutcome CalibrateDataset(const Dataset& dataset, const PipelineOptions& options,
                                    const ProgressCallback& progress) {
  std::vector<const PairEntry*> selected;
  const std::set<std::string> wanted(options.pair_ids.begin(), options.pair_ids.end());
  for (const PairEntry& pair : dataset.pairs)
    if (wanted.empty() || wanted.count(pair.id)) selected.push_back(&pair);

  std::vector<PairFeatures> features(selected.size());
  ParallelFor(
      selected.size(), options.threads,
      [&](size_t i) { features[i] = ExtractPairFeatures(dataset, *selected[i], options); },
      [&](int finished, size_t i) {
        if (progress) progress(finished, static_cast<int>(selected.size()), selected[i]->id);
      });
  return SolveFromFeatures(std::move(features), options);
}

CalibrationOutcome SolveFromFeatures(std::vector<PairFeatures> pairs,
                                     const PipelineOptions& options) {
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
  outcome.solution = solver.Run();
  return outcome;
}

PoseError ComputePoseError(const Pose& estimate, const Pose& reference) {
  return {(estimate.translation() - reference.translation()).norm(),
          RotationAngle(estimate.linear(), reference.linear())};
}

}  // namespace calibench
