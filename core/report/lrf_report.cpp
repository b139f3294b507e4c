// The LRF report: the outcome analysed (leave-one-out re-solves with the LRF pipeline's own
// solver) and written as one HTML page with the same pieces as the LiDAR-camera report.
#include "core/report/lrf_report.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/estimation/uncertainty.h"
#include "core/geometry/geometry.h"
#include "core/lrf/result_io.h"
#include "core/report/html_parts.h"
#include "core/results/export.h"

namespace calibench {
namespace {

using nlohmann::json;
using report_html::Escape;
using report_html::Num;
using report_html::Opt;

bool Solvable(const LrfPairFeatures& p) {
  return (p.three_face && p.three_face->scan.ok && p.three_face->depth.ok) ||
         (p.board_scan && p.board_scan->ok && p.camera);
}

// The target's own residual under `cam_from_lrf` (metres): Eq. (12) for the three-face target,
// the board scan points' RMS distance to the camera's board plane for the checkerboard.
std::optional<double> Residual(const LrfPairFeatures& p, const Pose& cam_from_lrf) {
  if (p.three_face && p.three_face->scan.ok && p.three_face->depth.ok)
    return PointToLineError(*p.three_face, cam_from_lrf);
  if (!(p.board_scan && p.board_scan->ok && p.camera) || p.board_scan->points.empty())
    return std::nullopt;
  double sum = 0.0;
  for (const Vec2& q : p.board_scan->points)
    sum += std::pow(p.camera->plane.SignedDistance(cam_from_lrf * Vec3(q.x(), q.y(), 0.0)), 2);
  return std::sqrt(sum / p.board_scan->points.size());
}

std::optional<double> Millimetres(const std::vector<double>& values, size_t i) {
  if (i >= values.size() || !std::isfinite(values[i])) return std::nullopt;
  return 1e3 * values[i];
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Leave-one-out over the solved observations: each left out (as a rejection would), the others
// solved with the same options, its residual predicted.
void CrossValidate(const LrfDataset& dataset, const LrfCalibrationOutcome& outcome,
                   const LrfPipelineOptions& options, const LrfReportOptions& report_options,
                   LrfReport* report) {
  const Pose& full = outcome.solution->cam_from_lrf;
  std::vector<LrfPairFeatures> light = outcome.pairs;
  for (LrfPairFeatures& p : light) p.depth.reset();  // the frames are for display only
  std::vector<size_t> solved;
  for (size_t i = 0; i < report->pairs.size(); ++i)
    if (report->pairs[i].solved) solved.push_back(i);
  if (solved.size() < 4) {
    report->cross_validation_skipped =
        std::to_string(solved.size()) + " observations solved; leaving one out needs at least 4";
    return;
  }
  // Without all six directions fixed, a solve of fewer observations wanders along the free ones:
  // its prediction would blame the observation left out for what no observation fixes.
  if (!report->well_constrained) {
    report->cross_validation_skipped =
        "the solve is not well constrained, so a solve without one observation moves freely along "
        "the directions none fixes and predicts nothing about it";
    return;
  }
  double train = 0.0, heldout = 0.0;
  std::vector<double> heldout_mm;
  int unconstrained = 0;
  for (size_t i : solved) {
    std::vector<LrfPairFeatures> without = light;
    without[i].status = PairStatus::kRejected;
    const LrfCalibrationOutcome fold = SolveLrfFromFeatures(std::move(without), dataset, options);
    if (!fold.solution) continue;
    if (!fold.solution->observability.well_constrained) {
      ++unconstrained;  // this observation alone fixes a direction: nothing predicts it
      continue;
    }
    const PoseError moved = ComputePoseError(fold.solution->cam_from_lrf, full);
    LrfPairReportRow& row = report->pairs[i];
    row.influence_mm = 1e3 * moved.translation_m;
    row.influence_deg = moved.rotation_rad * kRadToDeg;
    const std::optional<double> predicted = Residual(outcome.pairs[i], fold.solution->cam_from_lrf);
    if (!predicted || !row.residual_mm) continue;
    row.heldout_mm = 1e3 * *predicted;
    heldout_mm.push_back(*row.heldout_mm);
    train += std::pow(*row.residual_mm, 2);
    heldout += std::pow(*row.heldout_mm, 2);
    ++report->folds;
  }
  if (report->folds == 0) {
    report->cross_validation_skipped =
        unconstrained > 0 ? "every observation fixes a direction the others leave free"
                          : "no observation could be left out and solved without";
    return;
  }
  report->train_rms_mm = std::sqrt(train / report->folds);
  report->heldout_rms_mm = std::sqrt(heldout / report->folds);
  const double median = Median(heldout_mm);
  std::vector<double> deviations;
  for (double v : heldout_mm) deviations.push_back(std::abs(v - median));
  const double spread = 1.4826 * Median(deviations);
  std::string disagreeing;
  for (LrfPairReportRow& row : report->pairs) {
    if (!row.heldout_mm) continue;
    row.disagrees = *row.heldout_mm > median + report_options.disagree_sigmas * spread &&
                    *row.heldout_mm > report_options.min_ratio * median;
    if (row.disagrees)
      disagreeing += (disagreeing.empty() ? "" : ", ") + row.id + " (" + Num(*row.heldout_mm, 1) +
                     " mm held out)";
  }
  report->verdict = disagreeing.empty()
                        ? "consistent: every observation's held-out residual lies within " +
                              Num(report_options.disagree_sigmas, 1) +
                              " robust deviations of the median " + Num(median, 1) + " mm"
                        : "disagreeing: " + disagreeing + ", against a median of " +
                              Num(median, 1) + " mm; look at these observations, or reject them";
  if (unconstrained > 0)
    report->verdict += " (" + std::to_string(unconstrained) +
                       " observation(s) not predicted: without them the rest fix too little)";
}

// A 2D line a x + b y + c = 0 of the LRF plane (z = 0) where a camera-frame plane cuts it.
std::optional<Vec3> CutOfLrfPlane(const Plane& in_camera, const Pose& cam_from_lrf) {
  const Plane in_lrf = TransformPlane(cam_from_lrf.inverse(), in_camera);
  if (in_lrf.normal.head<2>().norm() < 1e-6) return std::nullopt;  // parallel to the scan
  return Vec3(in_lrf.normal.x(), in_lrf.normal.y(), in_lrf.distance);
}

// The scan from above (LRF x up, y left) around the target: the returns in grey, the target's in
// blue, the scan's corners in red, and the camera's faces (or board) cut with the LRF plane under
// the result in orange: where they miss the blue returns, the calibration (or the pair) is off.
std::string ScanSvg(const LrfPairFeatures& p, const Pose& cam_from_lrf) {
  std::vector<Vec2> target;
  std::vector<Plane> planes;
  std::vector<Vec2> corners;
  if (p.three_face && p.three_face->scan.ok) {
    for (const auto& face : p.three_face->scan.face_points)
      target.insert(target.end(), face.begin(), face.end());
    corners.assign(p.three_face->scan.corners.begin(), p.three_face->scan.corners.end());
    if (p.three_face->depth.ok)
      planes.assign(p.three_face->depth.planes.begin(), p.three_face->depth.planes.end());
  } else if (p.board_scan && p.board_scan->ok) {
    target = p.board_scan->points;
    if (p.camera) planes.push_back(p.camera->plane);
  }
  if (target.empty()) return "";
  Vec2 low = target.front(), high = target.front();
  for (const Vec2& q : target) low = low.cwiseMin(q), high = high.cwiseMax(q);
  low -= Vec2::Constant(0.3), high += Vec2::Constant(0.3);
  // View coordinates in metres: h = -y (right), v = -x (down); the viewBox does the scaling.
  const double width = high.y() - low.y(), height = high.x() - low.x();
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"360\" height=\"" +
                    Num(360.0 * height / width, 0) + "\" viewBox=\"" + Num(-high.y(), 4) + " " +
                    Num(-high.x(), 4) + " " + Num(width, 4) + " " + Num(height, 4) +
                    "\"><rect x=\"" + Num(-high.y(), 4) + "\" y=\"" + Num(-high.x(), 4) +
                    "\" width=\"" + Num(width, 4) + "\" height=\"" + Num(height, 4) +
                    "\" fill=\"#fafafa\"/>";
  const double dot = 0.004 * std::max(width, height);
  auto circle = [&](const Vec2& q, double r, const char* colour) {
    svg += "<circle cx=\"" + Num(-q.y(), 4) + "\" cy=\"" + Num(-q.x(), 4) + "\" r=\"" + Num(r, 4) +
           "\" fill=\"" + colour + "\"/>";
  };
  for (size_t i = 0; i < p.scan.ranges.size(); ++i) {
    if (!p.scan.Valid(i)) continue;
    const Vec2 q = p.scan.Point(i);
    if ((q.array() >= low.array()).all() && (q.array() <= high.array()).all())
      circle(q, dot, "#b0b0b0");
  }
  for (const Vec2& q : target) circle(q, dot, "#3b6ea5");
  for (const Plane& plane : planes) {
    const std::optional<Vec3> line = CutOfLrfPlane(plane, cam_from_lrf);
    if (!line) continue;
    const Vec2 normal = line->head<2>();
    const Vec2 foot = -line->z() * normal / normal.squaredNorm();
    const Vec2 along = Vec2(-normal.y(), normal.x()).normalized() * 2.0 * (width + height);
    const Vec2 a = foot - along, b = foot + along;
    svg += "<line x1=\"" + Num(-a.y(), 4) + "\" y1=\"" + Num(-a.x(), 4) + "\" x2=\"" +
           Num(-b.y(), 4) + "\" y2=\"" + Num(-b.x(), 4) + "\" stroke=\"#d98c2b\" stroke-width=\"" +
           Num(0.6 * dot, 4) + "\"/>";
  }
  for (const Vec2& c : corners) circle(c, 2.0 * dot, "#c0392b");
  return svg + "</svg>";
}

json ChartData(const LrfReport& r) {
  json pairs = json::array();
  for (const LrfPairReportRow& p : r.pairs) {
    auto value = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
    pairs.push_back({{"id", p.id},
                     {"solved", p.solved},
                     {"residual_mm", value(p.residual_mm)},
                     {"heldout_mm", value(p.heldout_mm)},
                     {"weight", value(p.weight)},
                     {"disagrees", p.disagrees}});
  }
  return {
      {"kind", "lrf"}, {"residual", r.residual_name}, {"pairs", pairs}, {"cost", r.cost_history}};
}

std::string ResultSection(const LrfReport& r) {
  ExportFrames frames;
  frames.lidar = "lrf";
  return "<section id=\"result\"><h2>Result</h2><div class=\"cards\">" +
         report_html::DirectionCards("lrf", "LRF", r.cam_from_lrf) + "</div>" +
         report_html::SigmaTable(r.sigma_t_mm, r.sigma_r_deg) +
         "<details><summary>The terminal's summary</summary><pre>" + Escape(r.summary) +
         "</pre></details>" + report_html::ExportSnippets(r.cam_from_lrf, frames) + "</section>";
}

std::string CrossValidationSection(const LrfReport& r) {
  std::string html = "<section id=\"cross-validation\"><h2>Held-out cross-validation</h2>";
  if (r.folds == 0)
    return html + "<p>Not computed: " + Escape(r.cross_validation_skipped) + ".</p></section>";
  const bool good = r.verdict.rfind("consistent", 0) == 0;
  return html + "<p class=\"verdict " + (good ? "good" : "bad") +
         "\">Verdict: " + Escape(r.verdict) + ".</p><p>Leave-one-out over " +
         std::to_string(r.folds) + " observations: each is left out, the rest solved, and its " +
         Escape(r.residual_name) +
         " predicted.</p><table class=\"sigma\"><tr><th></th><th>RMS [mm]</th></tr><tr><td>"
         "training</td><td>" +
         Num(r.train_rms_mm, 2) + "</td></tr><tr><td>held out</td><td>" + Num(r.heldout_rms_mm, 2) +
         "</td></tr></table></section>";
}

std::string PairTable(const LrfReport& r) {
  std::string html =
      "<section id=\"pairs\"><h2>Observations</h2><table class=\"pairs\"><thead><tr>"
      "<th>observation</th><th>status</th><th>" +
      Escape(r.residual_name) +
      " [mm]</th><th>scan points to faces, RMS [mm]</th><th>weight</th><th>without it: moves "
      "[mm / deg]</th><th>held out [mm]</th></tr></thead><tbody>";
  for (const LrfPairReportRow& p : r.pairs) {
    html += "<tr data-pair=\"" + Escape(p.id) + "\"" + (p.disagrees ? " class=\"disagrees\"" : "") +
            "><td>" + Escape(p.id) + "</td><td>" + PairStatusName(p.status) +
            (p.reason.empty() ? "" : "<br><small>" + Escape(p.reason) + "</small>") + "</td><td>" +
            Opt(p.residual_mm, 1) + "</td><td>" + Opt(p.point_to_plane_mm, 1) + "</td><td>" +
            Opt(p.weight, 2) + "</td><td>" + Opt(p.influence_mm, 2) + " / " +
            Opt(p.influence_deg, 3) + "</td><td>" + Opt(p.heldout_mm, 1) + "</td></tr>";
  }
  return html + "</tbody></table></section>";
}

std::string ScansSection(const LrfReport& r) {
  std::string html =
      "<section id=\"views\"><h2>Scans</h2><p>Each scan from above (the LRF's x up, y left) "
      "around the target: its returns in grey, the target's in blue, the scan's corners in red, "
      "and in orange the camera's " +
      std::string(r.target == LrfTargetType::kThreeFace ? "three faces" : "board plane") +
      " cut with the scan's plane under this result. Where orange misses blue, the calibration "
      "or the observation is off.</p><div class=\"figures\">";
  for (const LrfPairReportRow& p : r.pairs)
    if (!p.svg.empty())
      html += "<figure data-figure-pair=\"" + Escape(p.id) + "\">" + p.svg + "<figcaption>" +
              Escape(p.id) + (p.solved ? "" : " (not in the solve)") + "</figcaption></figure>";
  return html + "</div></section>";
}

}  // namespace

bool LrfReportOptions::Check(std::string* why) const {
  if (!(disagree_sigmas > 0 && min_ratio >= 1)) {
    if (why) *why = "need disagree_sigmas > 0 and min_ratio >= 1";
    return false;
  }
  return true;
}

LrfReport AnalyseLrfCalibration(const LrfDataset& dataset, const LrfCalibrationOutcome& outcome,
                                const LrfPipelineOptions& options,
                                const LrfReportOptions& report_options) {
  std::string why;
  if (!outcome.solution) throw std::invalid_argument("AnalyseLrfCalibration: no solution");
  if (!report_options.Check(&why)) throw std::invalid_argument("LrfReportOptions: " + why);
  const LrfSolution& s = *outcome.solution;
  LrfReport report;
  report.target = dataset.target_type;
  report.method = LrfMethodName(s.method);
  report.cam_from_lrf = s.cam_from_lrf;
  report.covariance = s.covariance;
  report.sigma_t_mm = 1000.0 * TranslationStd(s.covariance, s.cam_from_lrf);
  report.sigma_r_deg = RotationStdDeg(s.covariance, s.cam_from_lrf);
  report.well_constrained = s.observability.well_constrained;
  report.weak_directions = s.observability.weak_directions;
  report.residual_name = report.target == LrfTargetType::kThreeFace
                             ? "Eq. (12) corner-to-line distance"
                             : "board points to the camera's plane, RMS";
  report.summary = FormatLrfSummary(outcome);
  report.cost_history = s.cost_history;
  for (size_t i = 0; i < outcome.pairs.size(); ++i) {
    const LrfPairFeatures& p = outcome.pairs[i];
    LrfPairReportRow row;
    static_cast<PairStanding&>(row) = p;
    row.solved = p.status == PairStatus::kAccepted && Solvable(p);
    if (row.solved) {
      if (const auto residual = Residual(p, s.cam_from_lrf)) row.residual_mm = 1e3 * *residual;
      if (report.target == LrfTargetType::kThreeFace)
        row.point_to_plane_mm = Millimetres(s.point_to_plane_rms_m, i);
      if (i < s.robust_weights.size() && std::isfinite(s.robust_weights[i]))
        row.weight = s.robust_weights[i];
    }
    row.svg = ScanSvg(p, s.cam_from_lrf);
    report.pairs.push_back(std::move(row));
  }
  if (report_options.cross_validate)
    CrossValidate(dataset, outcome, options, report_options, &report);
  else
    report.cross_validation_skipped = "switched off (--no-cross-validation)";
  return report;
}

std::string LrfReportHtml(const LrfReport& report, const ReportProvenance& provenance,
                          const ReportAssets& assets) {
  int accepted = 0, solved = 0;
  for (const LrfPairReportRow& p : report.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    solved += p.solved;
  }
  const std::string pairs = std::to_string(report.pairs.size()) + " (" + std::to_string(accepted) +
                            " accepted, " + std::to_string(solved) + " in the solve)";
  const std::string target = report.target == LrfTargetType::kThreeFace
                                 ? "three-face target and a depth camera"
                                 : "checkerboard and an RGB camera";
  std::string body =
      "<header><h1>Calibench 2D LRF calibration report</h1>" +
      report_html::HeaderFacts(provenance, pairs, "method " + report.method + ", " + target);
  if (!report.well_constrained) {
    std::string weak;
    for (const std::string& w : report.weak_directions) weak += (weak.empty() ? "" : "; ") + w;
    body +=
        "<p class=\"verdict bad\">Not well constrained: " + Escape(weak) +
        ". The observations do not fix these directions: the values along them are not measured, "
        "and σ along them says so.</p>";
  }
  body += "</header>" + ResultSection(report) + CrossValidationSection(report);
  body += "<section id=\"plots\"><h2>Plots</h2><div class=\"plots\">";
  for (const char* plot : {"lrf-residuals", "weights", "convergence"})
    body += "<div class=\"plot\"><canvas id=\"" + std::string(plot) + "\"></canvas></div>";
  body += "</div></section>" + PairTable(report) + ScansSection(report);
  return report_html::FillReport("Calibench 2D LRF calibration report", body, ChartData(report),
                                 assets);
}

}  // namespace calibench
