#include "core/evaluation/crlb.h"

#include <cmath>

#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {

double MeasureCornerSigma(const Dataset& dataset) {
  double sum = 0.0;
  int count = 0;
  for (const PairEntry& pair : dataset.pairs) {
    const PairFeatures features = ExtractPairFeatures(dataset, pair, PipelineOptions{});
    if (!features.camera) continue;
    sum += features.camera->corner_sigma_px;
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

SimulationBoundInput MakeSimulationBoundInput(const SimOptions& options, double corner_sigma_px) {
  const SimOptions resolved = ResolveSimOptions(options);
  SimulationBoundInput input;
  input.pairs = SimulatePairTruth(resolved);
  input.camera = resolved.camera;
  input.board = resolved.board;
  input.cam_from_lidar = resolved.cam_from_lidar;
  input.range_sigma_m = options.lidar_range_noise_m;
  input.angular_sigma_rad = options.lidar_angular_noise_rad;
  input.corner_sigma_px = corner_sigma_px;
  return input;
}

std::vector<PlanePair> BoundPlanePairs(const SimulationBoundInput& input) {
  CALIBENCH_CHECK(input.range_sigma_m > 0 && input.corner_sigma_px > 0);
  const std::vector<Vec3> corners = BoardCornerPoints(input.board);
  std::vector<PlanePair> pairs;
  for (size_t k = 0; k < input.pairs.size(); ++k) {
    const SimPairTruth& truth = input.pairs[k];
    PlanePair pair;
    pair.id = std::to_string(k);
    const Plane board_in_cam{
        truth.cam_from_board.linear().col(2),
        -truth.cam_from_board.linear().col(2).dot(truth.cam_from_board.translation())};
    pair.camera_plane = OrientTowardsOrigin(board_in_cam);
    pair.lidar_plane =
        OrientTowardsOrigin(TransformPlane(input.cam_from_lidar.inverse(), pair.camera_plane));
    pair.lidar_covariance = LidarPlaneBoundCovariance(truth.lidar_board_points, pair.lidar_plane,
                                                      input.range_sigma_m, input.angular_sigma_rad);
    pair.camera_covariance = CameraPlaneBoundCovariance(input.camera, corners, truth.cam_from_board,
                                                        input.corner_sigma_px);
    pairs.push_back(pair);
  }
  return pairs;
}

CramerRaoBound SimulationBound(const SimulationBoundInput& input, const std::vector<int>& subset) {
  std::vector<PlanePair> all = BoundPlanePairs(input);
  std::vector<PlanePair> used;
  if (subset.empty()) {
    used = all;
  } else {
    for (int k : subset) used.push_back(all.at(k));
  }
  return BoundFromInformation(WeightedPlaneInformation(used, input.cam_from_lidar));
}

}  // namespace calibench
