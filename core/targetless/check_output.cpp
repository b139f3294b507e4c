// The check's report as text, as the `check --json` object (docs/targetless.md "Output"), and as
// a calibench.result.v1 file whose provenance says targetless.
#include "core/targetless/check_output.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/estimation/uncertainty.h"
#include "core/results/result_json.h"

namespace calibench {
namespace {

nlohmann::json Matrix(const Mat4& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::json Triple(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::string Line(const char* format, const Vec3& v) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, format, v.x(), v.y(), v.z());
  return buffer;
}

}  // namespace

std::string FormatCheckReport(const CheckReport& report) {
  std::string out = "verdict: " + CheckVerdictName(report.verdict) + "\n";
  out += "why: " + report.why + "\n";
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "frames used: %d of %d\n", report.frames_used,
                report.frames_given);
  out += buffer;
  if (!report.has_estimate) return out;
  std::snprintf(buffer, sizeof buffer,
                "alignment: %s, rms %.2f sigma; independent parts disagree %.1fx beyond their "
                "sigma (sigma scaled by it)\n",
                report.alignment.converged ? "converged" : "NOT converged",
                report.alignment.rms_sigma, std::sqrt(report.model_dispersion));
  out += buffer;
  out += Line(report.reference_is_guess ? "change from the guess: t [%+.1f %+.1f %+.1f] mm"
                                        : "change from the calibration: t [%+.1f %+.1f %+.1f] mm",
              report.change_t_m * 1e3);
  out += Line(", r [%+.3f %+.3f %+.3f] deg (camera axes)\n", report.change_r_deg);
  out += Line("targetless estimate sigma:   t [%.1f %.1f %.1f] mm", report.sigma_t_m * 1e3);
  out += Line(", r [%.3f %.3f %.3f] deg\n", report.sigma_r_deg);
  const Mat4 m = report.estimate.matrix();
  out += "targetless cam_from_lidar:\n";
  for (int r = 0; r < 3; ++r) {
    std::snprintf(buffer, sizeof buffer, "  [% .6f % .6f % .6f % .5f]\n", m(r, 0), m(r, 1), m(r, 2),
                  m(r, 3));
    out += buffer;
  }
  return out;
}

std::string CheckReportJson(const CheckReport& report) {
  nlohmann::json j;
  j["verdict"] = CheckVerdictName(report.verdict);
  j["guess"] = report.reference_is_guess;
  j["frames_used"] = report.frames_used;
  j["frames_given"] = report.frames_given;
  j["why"] = report.why;
  std::vector<std::string> axes;
  for (int a : report.unconstrained_axes) axes.push_back(CameraAxisName(a));
  j["unconstrained_axes"] = axes;
  j["reference_cam_from_lidar"] = Matrix(report.reference.matrix());
  if (report.has_estimate) {
    j["cam_from_lidar"] = Matrix(report.estimate.matrix());
    j["sigma_t_mm"] = Triple(report.sigma_t_m * 1e3);
    j["sigma_r_deg"] = Triple(report.sigma_r_deg);
    j["change_t_mm"] = Triple(report.change_t_m * 1e3);
    j["change_r_deg"] = Triple(report.change_r_deg);
    j["change_sigmas"] = report.change_sigmas;
    j["model_dispersion"] = report.model_dispersion;
    j["matched_edges"] = report.alignment.points_matched;
    j["image_cells"] = report.alignment.clusters;
    nlohmann::json rivals = nlohmann::json::array();
    for (size_t r = 0; r < report.rival_offsets.size(); ++r)
      rivals.push_back({{"offset_t_mm", Triple(report.rival_offsets[r].head<3>() * 1e3)},
                        {"offset_r_deg", Triple(report.rival_offsets[r].tail<3>() * kRadToDeg)},
                        {"frames_preferring", report.rival_frames_preferring[r]},
                        {"frames_deciding", report.rival_frames_decided[r]}});
    j["rival_alignments"] = rivals;
    j["weakest_profile"] = {{"direction", std::vector<double>(report.weakest_direction.data(),
                                                              report.weakest_direction.data() + 6)},
                            {"offsets_tolerance", report.weakest_offsets},
                            {"costs", report.weakest_costs}};
  } else {
    for (const char* key : {"cam_from_lidar", "sigma_t_mm", "sigma_r_deg", "change_t_mm",
                            "change_r_deg", "change_sigmas"})
      j[key] = nullptr;
    j["matched_edges"] = report.alignment.points_matched;
    j["image_cells"] = report.alignment.clusters;
  }
  j["axes"] = "camera axes: x right, y down, z forward; change = estimate minus the calibration";
  return j.dump();
}

namespace {

// The result file's header for a targetless estimate, provenance {kind: targetless, text}.
nlohmann::json TargetlessResultJson(const Pose& cam_from_lidar, const Mat6& right_covariance,
                                    const std::vector<std::string>& weak_directions,
                                    const std::string& provenance_text) {
  ObservabilityReport observability;
  observability.well_constrained = weak_directions.empty();
  observability.weak_directions = weak_directions;
  nlohmann::json root =
      ResultHeaderJson(ResultNames{}, cam_from_lidar, right_covariance, observability);
  root["method"] = "targetless";
  root["provenance"] = {{"kind", "targetless"}, {"text", provenance_text}};
  root["pairs"] = nlohmann::json::array();
  return root;
}

std::vector<std::string> UnconstrainedAxisNames(const CheckReport& report) {
  std::vector<std::string> names;
  for (int a : report.unconstrained_axes) names.push_back(CameraAxisName(a));
  return names;
}

}  // namespace

std::string TargetlessProvenanceText(const std::string& checked, const std::string& by) {
  return "estimated without a target by " + by + " from the scene's edges, around " + checked;
}

void WriteCheckResult(const std::filesystem::path& path, const CheckReport& report,
                      const std::filesystem::path& checked_result) {
  CALIBENCH_CHECK(report.has_estimate);
  nlohmann::json root = TargetlessResultJson(
      report.estimate, RightPerturbationCovariance(report.covariance, report.estimate),
      UnconstrainedAxisNames(report),
      TargetlessProvenanceText(checked_result.string(), "`calibench check`"));
  root["provenance"]["checked_result"] = checked_result.string();
  root["provenance"]["verdict"] = CheckVerdictName(report.verdict);
  root["provenance"]["guess"] = report.reference_is_guess;
  root["provenance"]["why"] = report.why;
  root["provenance"]["frames_used"] = report.frames_used;
  root["provenance"]["frames"] = report.frame_ids;
  WriteResultJson(path, root);
}

void WriteTargetlessResult(const std::filesystem::path& path, const Pose& cam_from_lidar,
                           const Mat6& right_covariance,
                           const std::vector<std::string>& weak_directions,
                           const std::string& provenance_text) {
  WriteResultJson(path, TargetlessResultJson(cam_from_lidar, right_covariance, weak_directions,
                                             provenance_text));
}

}  // namespace calibench
