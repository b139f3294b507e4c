#include "core/lrf_pipeline.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/json_io.h"
#include "core/parallel.h"
#include "core/result_io.h"

namespace calibench {
using nlohmann::json;

namespace {

std::string Millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f mm", metres * 1e3);
  return text;
}

bool HasFeatures(const LrfPairFeatures& pair) {
  if (pair.three_face) return pair.three_face->scan.ok && pair.three_face->depth.ok;
  return pair.board_scan && pair.board_scan->ok && pair.camera.has_value();
}

}  // namespace

bool LrfPipelineOptions::Check(std::string* why) const {
  if (!scan.Check(why) || !depth.Check(why) || !board_scan.Check(why) || !pnp.Check(why) ||
      !solver.Check(why))
    return false;
  if (!(adaptive_error_threshold_m >= 0) || !std::isfinite(adaptive_error_threshold_m)) {
    if (why) *why = "the adaptive error threshold must be >= 0 metres";
    return false;
  }
  if (threads < 1) {
    if (why) *why = "threads must be >= 1";
    return false;
  }
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

LrfCalibrationOutcome CalibrateLrfDataset(const LrfDataset& dataset,
                                          const LrfPipelineOptions& options,
                                          const LrfProgressCallback& progress) {
  std::vector<const LrfPairEntry*> selected;
  const std::set<std::string> wanted(options.pair_ids.begin(), options.pair_ids.end());
  for (const LrfPairEntry& pair : dataset.pairs)
    if (wanted.empty() || wanted.count(pair.id)) selected.push_back(&pair);
  std::vector<LrfPairFeatures> features(selected.size());
  ParallelFor(
      selected.size(), options.threads,
      [&](size_t i) { features[i] = ExtractLrfPairFeatures(dataset, *selected[i], options); },
      [&](int finished, size_t i) {
        if (progress) progress(finished, static_cast<int>(selected.size()), selected[i]->id);
      });
  return SolveLrfFromFeatures(std::move(features), dataset, options);
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

std::string LrfResultToJson(const LrfCalibrationOutcome& outcome,
                            const LrfPipelineOptions& options) {
  CALIBENCH_CHECK(outcome.solution.has_value());
  const LrfSolution& s = *outcome.solution;
  json root;
  root["format"] = "calibench.result.v1";
  root["direction"] = "x_in_cam = cam_from_lrf * x_in_lrf; lrf_from_cam is its inverse";
  root["cam_from_lrf"] = json_io::PoseToResultJson(s.cam_from_lrf);
  root["lrf_from_cam"] = json_io::PoseToResultJson(s.cam_from_lrf.inverse());
  json cov = json::array();
  for (int r = 0; r < 6; ++r) {
    json row = json::array();
    for (int c = 0; c < 6; ++c) row.push_back(s.covariance(r, c));
    cov.push_back(row);
  }
  root["covariance_6x6"] = cov;
  root["covariance_convention"] =
      "right perturbation cam_from_lrf * Exp(delta), delta = [rho (m); phi (rad)]";
  const Vec3 st = TranslationStd(s.covariance, s.cam_from_lrf);
  const Vec3 sr = RotationStdDeg(s.covariance, s.cam_from_lrf);
  root["std_translation_m"] = {st.x(), st.y(), st.z()};
  root["std_rotation_deg"] = {sr.x(), sr.y(), sr.z()};
  root["std_frame"] = "camera axes (x right, y down, z forward) of cam_from_lrf";
  root["observability"] = {
      {"eigenvalues", std::vector<double>(s.observability.eigenvalues.data(),
                                          s.observability.eigenvalues.data() + 6)},
      {"weak_directions", s.observability.weak_directions},
      {"well_constrained", s.observability.well_constrained}};
  json solver = {{"method", LrfMethodName(s.method)},
                 {"iterations", s.iterations},
                 {"converged", s.converged},
                 {"cost_history", s.cost_history},
                 {"huber_delta_m", options.solver.huber_delta_m},
                 {"mean_point_to_line_m", s.mean_point_to_line_m}};
  if (outcome.adaptive) {
    solver["adaptive"] = {{"error_threshold_m", options.adaptive_error_threshold_m},
                          {"observations_used", outcome.adaptive->observations_used},
                          {"reached_threshold", outcome.adaptive->reached_threshold},
                          {"newest_error_m", outcome.adaptive->newest_error_m}};
  }
  root["solver"] = solver;
  json pairs = json::array();
  for (size_t i = 0; i < outcome.pairs.size(); ++i) {
    const LrfPairFeatures& p = outcome.pairs[i];
    json entry = {{"id", p.id}, {"status", PairStatusName(p.status)}, {"reason", p.reason}};
    if (p.three_face && p.three_face->scan.ok) {
      const ScanFeatures& scan = p.three_face->scan;
      json corners = json::array();
      for (const Vec2& c : scan.corners) corners.push_back({c.x(), c.y()});
      entry["scan_corners_lrf"] = corners;
      entry["scan_rms_m"] = scan.rms_m;
    }
    if (p.three_face && p.three_face->depth.ok) {
      json planes = json::array();
      for (const Plane& plane : p.three_face->depth.planes)
        planes.push_back({plane.normal.x(), plane.normal.y(), plane.normal.z(), plane.distance});
      entry["depth_planes"] = planes;
      entry["depth_rms_m"] = p.three_face->depth.rms_m;
    }
    if (p.board_scan && p.board_scan->ok) {
      entry["board_scan_points"] = p.board_scan->points.size();
      entry["scan_rms_m"] = p.board_scan->rms_m;
    }
    if (p.camera) {
      const Plane& plane = p.camera->plane;
      entry["camera_plane"] = {plane.normal.x(), plane.normal.y(), plane.normal.z(),
                               plane.distance};
    }
    if (i < s.point_to_line_m.size() && std::isfinite(s.point_to_line_m[i]))
      entry["point_to_line_m"] = s.point_to_line_m[i];
    if (i < s.point_to_plane_rms_m.size() && std::isfinite(s.point_to_plane_rms_m[i]))
      entry["point_to_plane_rms_m"] = s.point_to_plane_rms_m[i];
    if (i < s.robust_weights.size() && std::isfinite(s.robust_weights[i]))
      entry["robust_weight"] = s.robust_weights[i];
    pairs.push_back(entry);
  }
  root["pairs"] = pairs;
  return root.dump(2) + "\n";
}

void WriteLrfResult(const std::filesystem::path& path, const LrfCalibrationOutcome& outcome,
                    const LrfPipelineOptions& options) {
  WriteFileAtomically(path, LrfResultToJson(outcome, options));
}

std::string LrfResidualText(const LrfSolution& solution, LrfTargetType target) {
  if (target == LrfTargetType::kThreeFace)
    return "Eq. (12) mean corner-to-line distance " + Millimetres(solution.mean_point_to_line_m);
  double sum_sq = 0.0;
  int count = 0;
  for (double rms : solution.point_to_plane_rms_m) {
    if (!std::isfinite(rms)) continue;
    sum_sq += rms * rms;
    ++count;
  }
  return "board point-to-plane RMS " + Millimetres(count ? std::sqrt(sum_sq / count) : 0.0);
}

std::string FormatLrfSummary(const LrfCalibrationOutcome& outcome) {
  std::ostringstream out;
  int accepted = 0;
  for (const LrfPairFeatures& p : outcome.pairs) {
    if (p.status == PairStatus::kAccepted) ++accepted;
    if (p.status == PairStatus::kFailed || p.status == PairStatus::kRejected)
      out << "  pair " << p.id << " " << PairStatusName(p.status) << ": " << p.reason << "\n";
  }
  out << accepted << " of " << outcome.pairs.size() << " observations usable\n";
  if (!outcome.solution) {
    out << "no calibration: " << outcome.failure << "\n";
    return out.str();
  }
  const LrfSolution& s = *outcome.solution;
  const Pose& pose = s.cam_from_lrf;
  const Vec3 t = pose.translation();
  const Vec3 rpy = LogSO3(pose.linear()) * 180.0 / M_PI;
  const Vec3 st = TranslationStd(s.covariance, pose) * 1e3;
  const Vec3 sr = RotationStdDeg(s.covariance, pose);
  const LrfTargetType target = !outcome.pairs.empty() && !outcome.pairs.front().three_face &&
                                       outcome.pairs.front().board_scan
                                   ? LrfTargetType::kCheckerboard
                                   : LrfTargetType::kThreeFace;
  char text[512];
  std::snprintf(text, sizeof(text),
                "method %s, %d iterations%s\n"
                "cam_from_lrf: translation [%.4f, %.4f, %.4f] m (std %.1f / %.1f / %.1f mm, "
                "camera axes)\n"
                "              rotation vector [%.3f, %.3f, %.3f] deg (std %.3f / %.3f / %.3f "
                "deg)\n"
                "%s\n",
                LrfMethodName(s.method).c_str(), s.iterations, s.converged ? ", converged" : "",
                t.x(), t.y(), t.z(), st.x(), st.y(), st.z(), rpy.x(), rpy.y(), rpy.z(), sr.x(),
                sr.y(), sr.z(), LrfResidualText(s, target).c_str());
  out << text;
  if (outcome.adaptive)
    out << "adaptive (Algorithm 1): " << outcome.adaptive->observations_used << " observations used"
        << (outcome.adaptive->reached_threshold ? ", below the threshold"
                                                : ", threshold not reached")
        << "\n";
  if (!s.observability.well_constrained) {
    out << "NOT WELL CONSTRAINED:";
    for (const std::string& w : s.observability.weak_directions) out << " " << w << ";";
    out << "\n";
  }
  return out.str();
}

}  // namespace calibench
