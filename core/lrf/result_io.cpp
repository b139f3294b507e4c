#include "core/lrf/result_io.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/estimation/uncertainty.h"
#include "core/results/result_json.h"

namespace calibench {
using nlohmann::json;

namespace {

std::string Millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f mm", metres * 1e3);
  return text;
}

json LrfResultToJson(const LrfCalibrationOutcome& outcome, const LrfPipelineOptions& options) {
  CALIBENCH_CHECK(outcome.solution.has_value());
  const LrfSolution& s = *outcome.solution;
  json root = ResultHeaderJson({"cam", "lrf"}, s.cam_from_lrf, s.covariance, s.observability);
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
    json entry = PairEntryJson(p.id, p.status, p.reason);
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
  return root;
}

}  // namespace

void WriteLrfResult(const std::filesystem::path& path, const LrfCalibrationOutcome& outcome,
                    const LrfPipelineOptions& options) {
  WriteResultJson(path, LrfResultToJson(outcome, options));
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
  const LrfTargetType target = !outcome.pairs.empty() && !outcome.pairs.front().three_face &&
                                       outcome.pairs.front().board_scan
                                   ? LrfTargetType::kCheckerboard
                                   : LrfTargetType::kThreeFace;
  // Both directions as matrices with their meaning in words, like the 3D method's summary.
  out << FormatTransform(ResultNames{"cam", "lrf"}, s.cam_from_lrf, s.covariance);
  out << "method " << LrfMethodName(s.method) << ", " << s.iterations << " iterations"
      << (s.converged ? ", converged" : "") << "\n"
      << LrfResidualText(s, target) << "\n";
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
