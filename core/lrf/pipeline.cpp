#include "core/lrf/pipeline.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/base/image.h"
#include "core/io/image_io.h"

namespace calibench {

namespace {

bool HasFeatures(const LrfPairFeatures& pair) {
  if (pair.three_face) return pair.three_face->scan.ok && pair.three_face->depth.ok;
  return pair.board_scan && pair.board_scan->ok && pair.camera.has_value();
}

}  // namespace

bool LrfPipelineOptions::Check(std::string* why) const {
  if (!scan.Check(why) || !depth.Check(why) || !board_scan.Check(why) || !pnp.Check(why) ||
      !solver.Check(why))
    return false;
  if (!(adaptive_error_threshold_m >= 0) || !std::isfinite(adaptive_error_threshold_m))
    return FailCheck(why, "the adaptive error threshold must be >= 0 metres");
  if (threads < 1) return FailCheck(why, "threads must be >= 1");
  return true;
}

LrfPairFeatures ExtractLrfPairFeatures(const LrfDataset& dataset, const LrfPairEntry& pair,
                                       const LrfPipelineOptions& options) {
  LrfPairFeatures features;
  features.id = pair.id;
  auto fail = [&](const std::string& reason) {
    features.status = PairStatus::kFailed;
    features.reason = reason;
    return features;
  };
  try {
    features.scan = LoadLaserScan(pair.scan);
  } catch (const IoError& e) {
    features.input_error = true;
    return fail(e.what());
  }
  const ScanRegion* region = pair.scan_region ? &*pair.scan_region : nullptr;
  if (dataset.target_type == LrfTargetType::kThreeFace) {
    DepthImage depth;
    try {
      depth = LoadPairDepth(dataset, pair);
    } catch (const IoError& e) {
      features.input_error = true;
      return fail(e.what());
    }
    LrfObservation observation;
    observation.id = pair.id;
    observation.scan = ExtractScanFeatures(features.scan, dataset.three_face, options.scan, region);
    observation.depth = ExtractDepthFeatures(depth, dataset.three_face, options.depth);
    features.depth = std::move(depth);
    features.three_face = observation;
    if (!observation.scan.ok) return fail("scan: " + observation.scan.reason);
    if (!observation.depth.ok) return fail("depth: " + observation.depth.reason);
  } else {
    ImageU8 image;
    try {
      image = LoadImage(pair.image);
    } catch (const IoError& e) {
      features.input_error = true;
      return fail(e.what());
    }
    if (image.width != dataset.camera.width || image.height != dataset.camera.height)
      return fail(pair.image.string() + ": image is " + std::to_string(image.width) + "x" +
                  std::to_string(image.height) + " but the camera is " +
                  std::to_string(dataset.camera.width) + "x" +
                  std::to_string(dataset.camera.height));
    features.board_scan = ExtractBoardScanPoints(features.scan, options.board_scan, region);
    if (!features.board_scan->ok) return fail("scan: " + features.board_scan->reason);
    std::string why;
    const auto detection = DetectBoard(image, dataset.board, options.detection, &why);
    if (!detection) return fail("camera: " + why);
    features.camera = EstimateBoardPose(dataset.camera, *detection, options.pnp, &why);
    if (!features.camera) return fail("camera: " + why);
  }
  features.status = PairStatus::kAccepted;
  return features;
}

LrfCalibrationOutcome SolveLrfFromFeatures(std::vector<LrfPairFeatures> pairs,
                                           const LrfDataset& dataset,
                                           const LrfPipelineOptions& options) {
  LrfCalibrationOutcome outcome;
  outcome.pairs = std::move(pairs);
  std::vector<int> used;  // indices into outcome.pairs, in order
  for (size_t i = 0; i < outcome.pairs.size(); ++i) {
    LrfPairFeatures& p = outcome.pairs[i];
    if (p.status == PairStatus::kPending && HasFeatures(p)) p.status = PairStatus::kAccepted;
    if (p.status == PairStatus::kAccepted && HasFeatures(p)) used.push_back(static_cast<int>(i));
  }
  if (used.size() < 2) {
    outcome.failure = "only " + std::to_string(used.size()) +
                      " usable observation(s); at least two with different target poses are "
                      "needed";
    return outcome;
  }
  LrfSolution solution;
  if (dataset.target_type == LrfTargetType::kThreeFace) {
    std::vector<LrfObservation> observations;
    for (int i : used) observations.push_back(*outcome.pairs[i].three_face);
    if (options.adaptive_error_threshold_m > 0) {
      outcome.adaptive =
          SolveLrfAdaptive(observations, options.adaptive_error_threshold_m, options.solver);
      solution = outcome.adaptive->solution;
    } else {
      solution = SolveLrf(observations, options.solver, dataset.initial_cam_from_lrf);
    }
  } else {
    std::vector<LrfBoardObservation> observations;
    for (int i : used) {
      const LrfPairFeatures& p = outcome.pairs[i];
      LrfBoardObservation o;
      o.id = p.id;
      o.board_points = p.board_scan->points;
      o.camera_plane = p.camera->plane;
      o.camera_plane_covariance = p.camera->plane_covariance;
      observations.push_back(o);
    }
    solution = SolveLrfBoard(observations, options.solver, dataset.initial_cam_from_lrf);
  }
  if (!solution.ok) {
    outcome.failure = solution.reason;
    return outcome;
  }
  // Per-observation figures are indexed by the solved list: spread them over the pairs.
  auto spread = [&](std::vector<double>& values) {
    std::vector<double> full(outcome.pairs.size(), std::nan(""));
    for (size_t k = 0; k < used.size() && k < values.size(); ++k) full[used[k]] = values[k];
    values = full;
  };
  spread(solution.point_to_line_m);
  spread(solution.point_to_plane_rms_m);
  spread(solution.robust_weights);
  outcome.solution = solution;
  return outcome;
}

}  // namespace calibench
