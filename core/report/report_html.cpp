// ReportHtml: the report's body written here, its look and plots in assets/report/.
#include "core/report/report_html.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/estimation/uncertainty.h"
#include "core/lidar_camera/time_offset.h"
#include "core/report/html_parts.h"
#include "core/results/export.h"

namespace calibench {
namespace {

using nlohmann::json;
using report_html::DirectionCards;
using report_html::Escape;
using report_html::ExportSnippets;
using report_html::FiguresSection;
using report_html::FillReport;
using report_html::HeaderFacts;
using report_html::Num;
using report_html::Opt;
using report_html::ReadText;
using report_html::SigmaTable;

std::string ResultSection(const CalibrationReport& r, const std::string& prefix) {
  return "<section id=\"" + prefix + "result\"><h2>Result</h2><div class=\"cards\">" +
         DirectionCards("lidar", "LiDAR", r.cam_from_lidar) + "</div>" +
         SigmaTable(r.sigma_t_mm, r.sigma_r_deg) + "<p>Solver: " + Escape(r.termination) +
         ". Options: " + Escape(r.options) +
         ".</p><details><summary>The terminal's summary</summary><pre>" + Escape(r.summary) +
         "</pre></details>" + ExportSnippets(r.cam_from_lidar, ExportFrames{}) + "</section>";
}

std::string PairTable(const CalibrationReport& r, const std::string& prefix) {
  std::string html =
      "<section id=\"" + prefix +
      "pairs\"><h2>Pairs</h2><table class=\"pairs\"><thead><tr><th>pair</th>"
      "<th>status</th><th>LiDAR board from</th><th>plane angle [deg]</th><th>plane offset "
      "[mm]</th><th>edge crossings / RMS [mm]</th><th>weight</th><th>without it: moves [mm / "
      "deg]</th><th>held out: angle [deg] / offset [mm] / "
      "sigma</th><th>remark</th></tr></thead><tbody>";
  for (const PairReportRow& p : r.pairs) {
    const bool worst = p.disagrees || p.down_weighted || !p.remark.empty();
    html += "<tr data-pair=\"" + Escape(p.id) + "\"" +
            (p.disagrees ? " class=\"disagrees\""
             : worst     ? " class=\"worst\""
                         : "") +
            "><td>" + Escape(p.id) + "</td><td>" + PairStatusName(p.status) +
            (p.reason.empty() ? "" : "<br><small>" + Escape(p.reason) + "</small>") + "</td><td>" +
            BoardSourceName(p.origin.source) +
            (p.origin.source == BoardSource::kNone ? "" : " " + Num(p.origin.confidence, 2)) +
            "</td><td>" + Opt(p.plane_angle_deg, 3) + "</td><td>" + Opt(p.plane_distance_mm, 1) +
            "</td><td>" +
            (p.solved ? std::to_string(p.edge_points) + " / " + Opt(p.edge_rms_mm, 1) : "&ndash;") +
            "</td><td>" + (p.solved ? Num(p.weight, 2) : "&ndash;") + "</td><td>" +
            Opt(p.influence_mm, 2) + " / " + Opt(p.influence_deg, 3) + "</td><td>" +
            Opt(p.heldout_angle_deg, 3) + " / " + Opt(p.heldout_distance_mm, 1) + " / " +
            Opt(p.heldout_sigmas, 1) + "</td><td>" + Escape(p.remark) + "</td></tr>";
  }
  return html + "</tbody></table></section>";
}

std::string CrossValidationSection(const CalibrationReport& r, const std::string& prefix) {
  std::string html =
      "<section id=\"" + prefix + "cross-validation\"><h2>Held-out cross-validation</h2>";
  if (!r.cross_validation)
    return html + "<p>Not computed: " + Escape(r.cross_validation_skipped) + ".</p></section>";
  const CrossValidation& cv = *r.cross_validation;
  return html + "<p class=\"verdict " + (cv.disagreeing.empty() ? "good" : "bad") +
         "\">Verdict: " + Escape(cv.verdict) + ".</p><p>Leave-one-out over " +
         std::to_string(cv.folds) +
         " pairs: each pair is left out, the rest solved, and the left-out pair's board plane "
         "predicted. Training residuals are at the full solution.</p><table class=\"sigma\"><tr>"
         "<th></th><th>plane angle RMS [deg]</th><th>plane offset RMS [mm]</th></tr><tr><td>"
         "training</td><td>" +
         Num(cv.train_rms_angle_deg, 3) + "</td><td>" + Num(cv.train_rms_distance_mm, 2) +
         "</td></tr><tr><td>held out</td><td>" + Num(cv.heldout_rms_angle_deg, 3) + "</td><td>" +
         Num(cv.heldout_rms_distance_mm, 2) + "</td></tr></table></section>";
}

// The time offset's profile for its plot: χ² above its lowest (twice the cost: the solve's cost is
// ½χ²) against the offset in ms, with the estimate and its σ.
json TimeOffsetData(const TimeOffsetEstimate& e) {
  if (e.profile_costs.empty()) return nullptr;
  const double lowest = *std::min_element(e.profile_costs.begin(), e.profile_costs.end());
  json offsets = json::array(), chi2 = json::array();
  for (size_t k = 0; k < e.profile_costs.size(); ++k) {
    offsets.push_back(e.profile_offsets_s[k] * 1e3);
    chi2.push_back(2.0 * (e.profile_costs[k] - lowest));
  }
  json data = {{"offset_ms", offsets}, {"chi2_above_lowest", chi2}};
  if (e.camera_minus_lidar_s) {
    data["estimate_ms"] = *e.camera_minus_lidar_s * 1e3;
    data["std_ms"] = e.std_s * 1e3;
  }
  return data;
}

// The clocks' offset in words, and its plot where the motion gave it a profile.
std::string TimeOffsetSection(const CalibrationReport& r, const std::string& prefix) {
  const TimeOffsetEstimate& e = r.time_offset;
  if (!e.camera_minus_lidar_s && e.moving_pairs == 0) return "";
  std::string how = e.camera_minus_lidar_s ? e.why : "";
  if (!how.empty()) how[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(how[0])));
  std::string html = "<section id=\"" + prefix + "time-offset\"><h2>Time offset</h2><p>" +
                     Escape(DescribeTimeOffset(e)) + "." +
                     (how.empty() ? "" : " " + Escape(how) + ".") + "</p>";
  if (!e.profile_costs.empty())
    html +=
        "<p>Each offset's solve of the moving pairs (planes whitened by both covariances, no "
        "robust weights): how much worse the planes agree than at the best offset. The "
        "estimate is the parabola's lowest point through the finest grid; its σ the "
        "curvature's.</p><div class=\"plots\"><div class=\"plot wide\"><canvas id=\"" +
        prefix + "time-offset-profile\"></canvas></div></div>";
  return html + "</section>";
}

json ChartData(const CalibrationReport& r) {
  json pairs = json::array();
  for (const PairReportRow& p : r.pairs) {
    json row = {{"id", p.id},
                {"status", PairStatusName(p.status)},
                {"solved", p.solved},
                {"weight", p.weight},
                {"disagrees", p.disagrees}};
    auto put = [&](const char* key, const std::optional<double>& v) {
      row[key] = v ? json(*v) : json(nullptr);
    };
    put("angle_deg", p.plane_angle_deg), put("distance_mm", p.plane_distance_mm);
    put("heldout_angle_deg", p.heldout_angle_deg),
        put("heldout_distance_mm", p.heldout_distance_mm);
    put("heldout_sigmas", p.heldout_sigmas);
    if (p.image_centre_px) row["image"] = {p.image_centre_px->x(), p.image_centre_px->y()};
    if (p.lidar_azimuth_elevation_deg)
      row["lidar"] = {p.lidar_azimuth_elevation_deg->x(), p.lidar_azimuth_elevation_deg->y()};
    pairs.push_back(row);
  }
  json sigma = json::array();
  for (const SigmaStep& s : r.sigma_history)
    sigma.push_back({{"pairs", s.pairs},
                     {"t_mm", {s.sigma_t_mm.x(), s.sigma_t_mm.y(), s.sigma_t_mm.z()}},
                     {"r_deg", {s.sigma_r_deg.x(), s.sigma_r_deg.y(), s.sigma_r_deg.z()}}});
  return {{"pairs", pairs},
          {"cost", r.cost_history},
          {"sigma", sigma},
          {"image_size", {r.image_width, r.image_height}},
          {"time_offset", TimeOffsetData(r.time_offset)}};
}

}  // namespace

ReportAssets LoadReportAssets(const std::filesystem::path& report_dir,
                              const std::filesystem::path& chart_js) {
  ReportAssets assets;
  assets.html_template = ReadText(report_dir / "report.html", "the report's template");
  assets.style = ReadText(report_dir / "report.css", "the report's style");
  assets.script = ReadText(report_dir / "report.js", "the report's plots");
  assets.chart_js = ReadText(chart_js, "Chart.js (apt-get install libjs-chart.js)");
  return assets;
}

std::string CoverageGaps(const CalibrationReport& r) {
  static constexpr std::array<const char*, 3> kRows = {"top", "middle", "bottom"};
  static constexpr std::array<const char*, 3> kCols = {"left", "centre", "right"};
  bool seen[3][3] = {};
  double az_min = 1e9, az_max = -1e9, el_min = 1e9, el_max = -1e9;
  for (const PairReportRow& p : r.pairs) {
    if (!p.solved) continue;
    if (p.image_centre_px && r.image_width > 0 && r.image_height > 0) {
      const int c = std::clamp(static_cast<int>(3 * p.image_centre_px->x() / r.image_width), 0, 2);
      const int row =
          std::clamp(static_cast<int>(3 * p.image_centre_px->y() / r.image_height), 0, 2);
      seen[row][c] = true;
    }
    if (p.lidar_azimuth_elevation_deg) {
      az_min = std::min(az_min, p.lidar_azimuth_elevation_deg->x());
      az_max = std::max(az_max, p.lidar_azimuth_elevation_deg->x());
      el_min = std::min(el_min, p.lidar_azimuth_elevation_deg->y());
      el_max = std::max(el_max, p.lidar_azimuth_elevation_deg->y());
    }
  }
  std::string empty;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c)
      if (!seen[row][c])
        empty +=
            (empty.empty() ? "" : ", ") +
            (row == 1 && c == 1 ? std::string("centre") : std::string(kRows[row]) + " " + kCols[c]);
  std::string words;
  if (!empty.empty()) words = "no board centre in the image's " + empty + ".";
  if (az_max >= az_min && az_max - az_min < 20.0)
    words += std::string(words.empty() ? "" : " ") + "The boards span only " +
             Num(az_max - az_min, 0) + " deg of the LiDAR's azimuth.";
  if (el_max >= el_min && el_max - el_min < 20.0)
    words += std::string(words.empty() ? "" : " ") + "The boards span only " +
             Num(el_max - el_min, 0) + " deg of the LiDAR's elevation.";
  return words;
}

namespace {

std::string PairsFact(const CalibrationReport& report) {
  int accepted = 0, solved = 0;
  for (const PairReportRow& p : report.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    solved += p.solved;
  }
  return std::to_string(report.pairs.size()) + " (" + std::to_string(accepted) + " accepted, " +
         std::to_string(solved) + " in the solve)";
}

// One camera's result, cross-validation, plots, pairs and views; every id starts with `prefix`
// (report.js draws the plots of each camera's canvases).
std::string CameraBody(const CalibrationReport& report, const std::vector<ReportFigure>& figures,
                       const std::string& prefix) {
  std::string body = ResultSection(report, prefix) + CrossValidationSection(report, prefix);
  const std::string gaps = CoverageGaps(report);
  body += "<section id=\"" + prefix + "plots\"><h2>Plots</h2><div class=\"plots\">";
  for (const char* plot :
       {"residuals", "weights", "convergence", "sigma", "coverage-image", "coverage-lidar"})
    body += "<div class=\"plot\"><canvas id=\"" + prefix + plot + "\"></canvas></div>";
  body += "</div><p class=\"coverage\">Coverage: " +
          Escape(gaps.empty() ? "the boards cover the image's 3 x 3 grid and a wide LiDAR field."
                              : gaps + " More poses there would help.") +
          "</p></section>";
  return body + TimeOffsetSection(report, prefix) + PairTable(report, prefix) +
         FiguresSection(figures, prefix);
}

std::string SigmaCells(const Vec3& t_mm, const Vec3& r_deg) {
  return "<td>" + Num(t_mm.x(), 2) + " " + Num(t_mm.y(), 2) + " " + Num(t_mm.z(), 2) + "</td><td>" +
         Num(r_deg.x(), 3) + " " + Num(r_deg.y(), 3) + " " + Num(r_deg.z(), 3) + "</td>";
}

}  // namespace

std::string ReportHtml(const CalibrationReport& report, const ReportProvenance& provenance,
                       const std::vector<ReportFigure>& figures, const ReportAssets& assets,
                       const std::string& extra_sections) {
  std::string body = "<header><h1>Calibench calibration report</h1>" +
                     HeaderFacts(provenance, PairsFact(report), report.options);
  if (!report.distrust.empty())
    body += "<p class=\"verdict bad\">" + Escape(report.distrust) + "</p>";
  body += "</header>" + CameraBody(report, figures, "") + extra_sections;
  return FillReport("Calibench calibration report", body, ChartData(report), assets);
}

std::string RigReportHtml(const RigReportSummary& rig, const std::vector<RigCameraReport>& cameras,
                          const ReportProvenance& provenance, const ReportAssets& assets) {
  std::string body = "<header><h1>Calibench rig calibration report</h1>";
  std::string names;
  for (const RigCameraReport& camera : cameras) names += (names.empty() ? "" : ", ") + camera.name;
  body += HeaderFacts(provenance,
                      std::to_string(cameras.size()) + " cameras (" + names + "), " +
                          std::to_string(rig.shared_captures) + " captures seen by two or more",
                      cameras.empty() ? "" : cameras.front().report.options);
  body += "<nav class=\"cameras\">";
  for (const RigCameraReport& camera : cameras)
    body += "<a href=\"#" + Escape(camera.prefix) + "camera\">" + Escape(camera.name) + "</a> ";
  body += "</nav></header>";
  // The rig: each camera's pose from the joint solve next to its own, and the cameras' relative
  // poses, which only the joint solve ties with boards two cameras saw at once.
  body +=
      "<section id=\"rig\"><h2>The rig</h2><p>Every camera with the LiDAR in one problem (the "
      "rig solve); the camera sections below are each camera alone, as <code>calibrate</code> "
      "solves one camera.</p><table class=\"sigma\"><tr><th>camera</th><th>pairs</th>"
      "<th>rig: translation [m]</th><th>rig: sigma t [mm] (x y z)</th><th>rig: sigma r [deg]</th>"
      "<th>alone: sigma t [mm]</th><th>alone: sigma r [deg]</th><th>rig vs alone [mm / "
      "deg]</th></tr>";
  for (const RigReportSummary::Camera& camera : rig.cameras) {
    const Vec3 t = camera.cam_from_lidar.translation();
    const double moved_mm = 1e3 * (t - camera.single_cam_from_lidar.translation()).norm();
    const double turned_deg = Eigen::AngleAxisd(camera.cam_from_lidar.linear().transpose() *
                                                camera.single_cam_from_lidar.linear())
                                  .angle() *
                              kRadToDeg;
    body += "<tr data-rig-camera=\"" + Escape(camera.name) + "\"><td>" + Escape(camera.name) +
            "</td><td>" + std::to_string(camera.pairs) + "</td><td>" + Num(t.x(), 4) + " " +
            Num(t.y(), 4) + " " + Num(t.z(), 4) + "</td>" +
            SigmaCells(camera.sigma_t_mm, camera.sigma_r_deg) +
            SigmaCells(camera.single_sigma_t_mm, camera.single_sigma_r_deg) + "<td>" +
            Num(moved_mm, 2) + " / " + Num(turned_deg, 3) + "</td></tr>";
  }
  body +=
      "</table><h3>Cameras relative to each other</h3><table class=\"sigma\"><tr>"
      "<th>pose</th><th>translation [m]</th><th>sigma t [mm] (x y z)</th>"
      "<th>sigma r [deg]</th></tr>";
  for (const PoseWithSigmas& relative : rig.relative) {
    const Vec3 t = relative.pose.translation();
    body += "<tr data-relative=\"" + Escape(relative.name) + "\"><td><code>" +
            Escape(relative.name) + "</code></td><td>" + Num(t.x(), 4) + " " + Num(t.y(), 4) + " " +
            Num(t.z(), 4) + "</td>" + SigmaCells(relative.sigma_t_mm, relative.sigma_r_deg) +
            "</tr>";
  }
  body += "</table></section>";
  json data = {{"cameras", json::array()}};
  for (const RigCameraReport& camera : cameras) {
    body += "<section class=\"camera\" id=\"" + Escape(camera.prefix) + "camera\"><h2>Camera " +
            Escape(camera.name) + " alone</h2>";
    if (!camera.report.distrust.empty())
      body += "<p class=\"verdict bad\">" + Escape(camera.report.distrust) + "</p>";
    body += "<p>pairs: " + PairsFact(camera.report) + "</p>" +
            CameraBody(camera.report, camera.figures, camera.prefix) + "</section>";
    json chart = ChartData(camera.report);
    chart["prefix"] = camera.prefix;
    data["cameras"].push_back(chart);
  }
  return FillReport("Calibench rig calibration report", body, data, assets);
}

RigReportSummary SummarizeRigOutcome(const RigOutcome& outcome) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  RigReportSummary summary;
  summary.shared_captures = outcome.shared_captures;
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const SolverResult& single = *outcome.single[c].solution;
    const PoseWithSigmas joint = RigJointPose(outcome, c);
    summary.cameras.push_back({outcome.camera_names[c], AcceptedPairs(outcome.single[c]),
                               joint.pose, joint.sigma_t_mm, joint.sigma_r_deg,
                               single.cam_from_lidar,
                               1e3 * TranslationStd(single.covariance, single.cam_from_lidar),
                               RotationStdDeg(single.covariance, single.cam_from_lidar)});
  }
  summary.relative = RigRelativePoses(outcome);
  return summary;
}

}  // namespace calibench
