// AnalyseCalibration: per-pair figures, leave-one-out cross-validation and σ as pairs accumulate,
// all by re-solving with SolveFromFeatures.
#include "core/report/calibration_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/base/parallel.h"
#include "core/base/statistics.h"
#include "core/estimation/uncertainty.h"
#include "core/lidar_camera/result_io.h"

namespace calibench {
namespace {

struct PlaneError {
  double angle_deg = 0.0;
  double distance_mm = 0.0;  // signed: the LiDAR plane's offset minus the camera's
};

// The LiDAR board plane carried into the camera against the camera's board plane (Eq. (6)'s two
// parts in words: the normals' angle and the offsets' difference).
PlaneError PlaneErrorAt(const Pose& cam_from_lidar, const LidarPlaneFit& lidar,
                        const CameraBoardObservation& camera) {
  const Plane predicted = OrientTowardsOrigin(TransformPlane(cam_from_lidar, lidar.plane));
  const Plane observed = OrientTowardsOrigin(camera.plane);
  const double cosine = std::clamp(predicted.normal.dot(observed.normal), -1.0, 1.0);
  return {std::acos(cosine) * kRadToDeg, 1000.0 * (predicted.distance - observed.distance)};
}

// RMS distance (mm) of the pair's board-edge crossings to the sheet's edges, in the board frame
// the camera's PnP gives; nullopt without crossings.
std::optional<double> EdgeRmsMm(const Pose& cam_from_lidar, const LidarPlaneFit& lidar,
                                const CameraBoardObservation& camera, const BoardSpec& target) {
  if (lidar.edge_points.empty()) return std::nullopt;
  const Pose board_from_lidar = camera.cam_from_board.inverse() * cam_from_lidar;
  const double hw = 0.5 * target.SheetWidth(), hh = 0.5 * target.SheetHeight();
  double sum = 0.0;
  for (const LidarEdgePoint& edge : lidar.edge_points) {
    const Vec3 p = board_from_lidar * edge.point;
    const double outside = std::max(std::abs(p.x()) - hw, std::abs(p.y()) - hh);
    sum += outside * outside;
  }
  return 1000.0 * std::sqrt(sum / lidar.edge_points.size());
}

// The held-out plane error in units of its own σ: the residual [tangent part of the normal
// difference; offset difference] against both planes' covariances (the LiDAR's with its ring
// biases) and the pipeline's floors, in quadrature.
double PlaneErrorSigmas(const Pose& cam_from_lidar, const LidarPlaneFit& lidar,
                        const CameraBoardObservation& camera, const PipelineOptions& options) {
  const Plane observed = OrientTowardsOrigin(camera.plane);
  Plane predicted = TransformPlane(cam_from_lidar, lidar.plane);
  double sign = 1.0;
  if (predicted.normal.dot(observed.normal) < 0) sign = -1.0;
  predicted.normal *= sign, predicted.distance *= sign;
  // d(n_cam, d_cam)/d(n_lidar, d_lidar) for n_c = R n_l, d_c = d_l - n_c . t.
  const Mat3& R = cam_from_lidar.linear();
  Mat4 J = Mat4::Zero();
  J.topLeftCorner<3, 3>() = sign * R;
  J.block<1, 3>(3, 0) = -sign * cam_from_lidar.translation().transpose() * R;
  J(3, 3) = sign;
  const Mat4 lidar_cov = J * (lidar.covariance + lidar.ring_bias_covariance) * J.transpose();
  // The tangent plane of the observed normal and the offset: three independent residuals.
  const Vec3 n = observed.normal;
  const Vec3 b1 = n.unitOrthogonal(), b2 = n.cross(b1);
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  P.block<1, 3>(0, 0) = b1.transpose();
  P.block<1, 3>(1, 0) = b2.transpose();
  P(2, 3) = 1.0;
  const Vec4 r4(predicted.normal.x() - n.x(), predicted.normal.y() - n.y(),
                predicted.normal.z() - n.z(), predicted.distance - observed.distance);
  const Vec3 r = P * r4;
  Mat3 C = P * (lidar_cov + camera.plane_covariance) * P.transpose();
  const double floor_rad = options.guided_floor_sigma_deg / kRadToDeg;
  C += Vec3(floor_rad * floor_rad, floor_rad * floor_rad,
            options.guided_floor_sigma_m * options.guided_floor_sigma_m)
           .asDiagonal();
  return std::sqrt(r.dot(C.ldlt().solve(r)));
}

bool Solvable(const PairFeatures& p) {
  return (p.status == PairStatus::kAccepted || p.status == PairStatus::kPending) && p.lidar &&
         p.camera;
}

// The solve of the pairs `keep` selects among the solvable ones (the others rejected), started
// at `start`; nullopt when it fails.
std::optional<SolverResult> SolveSubset(const std::vector<PairFeatures>& pairs,
                                        const std::vector<bool>& keep, PipelineOptions options,
                                        const Pose& start, bool with_covariance) {
  std::vector<PairFeatures> subset = pairs;
  for (size_t i = 0; i < subset.size(); ++i)
    if (!keep[i] && Solvable(subset[i])) subset[i].status = PairStatus::kRejected;
  options.initial_cam_from_lidar = start;
  options.solver.jackknife_covariance = options.solver.jackknife_covariance && with_covariance;
  return SolveFromFeatures(std::move(subset), options).solution;
}

double RotationAngleDeg(const Mat3& a, const Mat3& b) {
  const double cosine = std::clamp(0.5 * ((a.transpose() * b).trace() - 1.0), -1.0, 1.0);
  return std::acos(cosine) * kRadToDeg;
}

// Whether `value` stands out of `others`: beyond their median by `sigmas` robust standard
// deviations (1.4826 MAD) and above `floor`.
bool StandsOut(double value, const std::vector<double>& others, double sigmas, double floor) {
  const double median = Median(others);
  std::vector<double> deviations;
  for (const double o : others) deviations.push_back(std::abs(o - median));
  const double scale = 1.4826 * Median(deviations);
  return value > std::max(floor, median + sigmas * scale);
}

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

std::string OptionsInWords(const PipelineOptions& o) {
  std::string words =
      "method " + SolverMethodName(o.solver.method) + ", Huber delta " +
      Fixed(o.solver.method == SolverMethod::kWeightedMl ? o.solver.whitened_huber_delta
                                                         : o.solver.huber_delta,
            2) +
      (o.solver.method == SolverMethod::kWeightedMl ? " sigma" : "");
  if (o.solver.method == SolverMethod::kWeightedMl)
    words += std::string(", board edges ") + (o.solver.use_board_edges ? "on" : "off") +
             ", range offset " + (o.solver.estimate_range_offset ? "estimated" : "fixed at 0");
  words += std::string(", board detection ") + (o.detect_board ? "on" : "off") +
           ", camera-guided completion " + (o.camera_guided ? "on" : "off");
  if (o.lidar_model) words += ", LiDAR model forced to " + LidarGeometryName(*o.lidar_model);
  return words;
}

void FillCoverage(const Dataset& dataset, const PairFeatures& p, PairReportRow* row) {
  if (p.camera)
    row->image_centre_px = dataset.camera.Project(p.camera->cam_from_board.translation());
  if (p.lidar) {
    const Vec3& c = p.lidar->inlier_centroid;
    row->lidar_azimuth_elevation_deg =
        Vec2(std::atan2(c.y(), c.x()), std::atan2(c.z(), std::hypot(c.x(), c.y()))) * kRadToDeg;
  }
}

// Leave one solved pair out at a time: the move of the result and the held-out plane error.
void CrossValidate(const Dataset& dataset, const CalibrationOutcome& outcome,
                   const PipelineOptions& options, const ReportOptions& ro,
                   const std::vector<size_t>& solved, CalibrationReport* report) {
  const SolverResult& full = *outcome.solution;
  std::vector<std::optional<Pose>> without(solved.size());
  ParallelFor(solved.size(), options.threads, [&](size_t k) {
    std::vector<bool> keep(outcome.pairs.size(), true);
    keep[solved[k]] = false;
    if (auto s = SolveSubset(outcome.pairs, keep, options, full.cam_from_lidar, false))
      without[k] = s->cam_from_lidar;
  });
  CrossValidation cv;
  std::vector<double> sigmas;
  double train_a = 0, train_d = 0, held_a = 0, held_d = 0;
  for (size_t k = 0; k < solved.size(); ++k) {
    PairReportRow& row = report->pairs[solved[k]];
    const PairFeatures& p = outcome.pairs[solved[k]];
    if (!without[k]) continue;  // the others alone do not fix the pose
    row.influence_mm =
        1000.0 * (without[k]->translation() - full.cam_from_lidar.translation()).norm();
    row.influence_deg = RotationAngleDeg(without[k]->linear(), full.cam_from_lidar.linear());
    const PlaneError held = PlaneErrorAt(*without[k], *p.lidar, *p.camera);
    row.heldout_angle_deg = held.angle_deg;
    row.heldout_distance_mm = held.distance_mm;
    row.heldout_sigmas = PlaneErrorSigmas(*without[k], *p.lidar, *p.camera, options);
    sigmas.push_back(*row.heldout_sigmas);
    train_a += std::pow(*row.plane_angle_deg, 2), train_d += std::pow(*row.plane_distance_mm, 2);
    held_a += held.angle_deg * held.angle_deg, held_d += held.distance_mm * held.distance_mm;
    ++cv.folds;
  }
  if (cv.folds < 4) {
    report->cross_validation_skipped =
        "fewer than 4 pairs whose absence leaves the pose determined";
    return;
  }
  cv.train_rms_angle_deg = std::sqrt(train_a / cv.folds);
  cv.train_rms_distance_mm = std::sqrt(train_d / cv.folds);
  cv.heldout_rms_angle_deg = std::sqrt(held_a / cv.folds);
  cv.heldout_rms_distance_mm = std::sqrt(held_d / cv.folds);
  size_t fold = 0;
  for (const size_t index : solved) {
    PairReportRow& row = report->pairs[index];
    if (!row.heldout_angle_deg) continue;
    std::vector<double> others = sigmas;
    others.erase(others.begin() + fold);
    ++fold;
    row.disagrees = StandsOut(*row.heldout_sigmas, others, ro.disagree_sigmas, ro.min_sigmas);
    if (row.disagrees) cv.disagreeing.push_back(row.id);
  }
  const std::string figures = "held-out RMS " + Fixed(cv.heldout_rms_angle_deg, 2) + " deg, " +
                              Fixed(cv.heldout_rms_distance_mm, 1) + " mm against training " +
                              Fixed(cv.train_rms_angle_deg, 2) + " deg, " +
                              Fixed(cv.train_rms_distance_mm, 1) + " mm over " +
                              std::to_string(cv.folds) + " pairs";
  if (cv.disagreeing.empty()) {
    cv.verdict = "consistent: every pair's plane is predicted by the others as well as the rest (" +
                 figures + ")";
  } else {
    std::string names;
    for (const std::string& id : cv.disagreeing) names += (names.empty() ? "" : ", ") + id;
    const bool one = cv.disagreeing.size() == 1;
    cv.verdict = std::string(one ? "pair " : "pairs ") + names +
                 (one ? " disagrees" : " disagree") + ": the other pairs predict " +
                 (one ? "its board plane" : "their board planes") +
                 ", in units of its own sigma, far worse than each other's (" + figures + ")";
  }
  report->cross_validation = cv;
}

void SigmaHistory(const CalibrationOutcome& outcome, const PipelineOptions& options,
                  const std::vector<size_t>& solved, CalibrationReport* report) {
  const size_t first = static_cast<size_t>(std::max(options.min_pairs, 3));
  std::vector<std::optional<SigmaStep>> steps(solved.size() + 1);
  std::vector<size_t> counts;
  for (size_t k = first; k <= solved.size(); ++k) counts.push_back(k);
  ParallelFor(counts.size(), options.threads, [&](size_t c) {
    const size_t k = counts[c];
    std::vector<bool> keep(outcome.pairs.size(), false);
    for (size_t i = 0; i < k; ++i) keep[solved[i]] = true;
    const auto s =
        SolveSubset(outcome.pairs, keep, options, outcome.solution->cam_from_lidar, true);
    if (!s) return;
    steps[k] =
        SigmaStep{static_cast<int>(k), 1000.0 * TranslationStd(s->covariance, s->cam_from_lidar),
                  RotationStdDeg(s->covariance, s->cam_from_lidar)};
  });
  for (const auto& step : steps)
    if (step) report->sigma_history.push_back(*step);
}

void MarkWorstRows(CalibrationReport* report) {
  PairReportRow* most = nullptr;
  for (PairReportRow& row : report->pairs) {
    if (row.influence_mm && (!most || *row.influence_mm > *most->influence_mm)) most = &row;
    if (row.down_weighted) row.remark = "down-weighted to nothing by the robust kernel";
    if (row.disagrees)
      row.remark = "disagrees with the other pairs (held-out error " +
                   Fixed(*row.heldout_angle_deg, 2) + " deg, " +
                   Fixed(*row.heldout_distance_mm, 1) + " mm = " + Fixed(*row.heldout_sigmas, 1) +
                   " sigma): distrust this pair";
  }
  const double sigma_norm_mm = report->sigma_t_mm.norm();
  if (most && most->remark.empty())
    most->remark = "moves the result most: " + Fixed(*most->influence_mm, 1) + " mm, " +
                   Fixed(*most->influence_deg, 3) + " deg without it" +
                   (*most->influence_mm > sigma_norm_mm ? " (more than the reported sigma)" : "");
  std::string distrust;
  for (const PairReportRow& row : report->pairs)
    if (row.disagrees) distrust += (distrust.empty() ? "" : ", ") + row.id;
  if (!distrust.empty()) {
    report->distrust = "Distrust " + distrust +
                       ": held out, the other pairs predict its board plane far worse than each "
                       "other's (a board that moved between the LiDAR's and the camera's "
                       "capture, a wrong board in the cloud, a bent sheet). Look at it, reject it "
                       "if so, and re-solve.";
  } else if (most && *most->influence_mm > sigma_norm_mm) {
    report->distrust = "No pair disagrees, but " + most->id + " alone moves the result by " +
                       Fixed(*most->influence_mm, 1) +
                       " mm, more than the reported sigma: more poses like it would steady it.";
  }
}

}  // namespace

bool ReportOptions::Check(std::string* why) const {
  if (!(disagree_sigmas > 0.0 && min_sigmas >= 0.0)) {
    *why = "report: disagree_sigmas must be > 0 and min_sigmas >= 0";
    return false;
  }
  return true;
}

CalibrationReport AnalyseCalibration(const Dataset& dataset, const CalibrationOutcome& outcome,
                                     const PipelineOptions& options,
                                     const ReportOptions& report_options) {
  if (!outcome.solution) throw std::invalid_argument("no solution to report: " + outcome.failure);
  const SolverResult& s = *outcome.solution;
  CalibrationReport report;
  report.cam_from_lidar = s.cam_from_lidar;
  report.covariance = s.covariance;
  report.sigma_t_mm = 1000.0 * TranslationStd(s.covariance, s.cam_from_lidar);
  report.sigma_r_deg = RotationStdDeg(s.covariance, s.cam_from_lidar);
  report.method = SolverMethodName(s.method);
  report.options = OptionsInWords(options);
  report.summary = FormatSummary(outcome);
  report.termination = s.termination.Describe();
  report.cost_history = s.cost_history;
  report.time_offset = outcome.time_offset;
  report.image_width = dataset.camera.width;
  report.image_height = dataset.camera.height;
  std::vector<size_t> solved;
  for (size_t i = 0; i < outcome.pairs.size(); ++i) {
    const PairFeatures& p = outcome.pairs[i];
    PairReportRow row;
    row.id = p.id, row.status = p.status, row.reason = p.reason, row.origin = p.board_origin;
    FillCoverage(dataset, p, &row);
    if (Solvable(p)) {
      const size_t k = solved.size();
      solved.push_back(i);
      row.solved = true;
      row.weight = k < s.robust_weights.size() ? s.robust_weights[k] : 0.0;
      row.down_weighted = s.DownWeighted(k);
      const PlaneError e = PlaneErrorAt(s.cam_from_lidar, *p.lidar, *p.camera);
      row.plane_angle_deg = e.angle_deg, row.plane_distance_mm = e.distance_mm;
      row.edge_points = static_cast<int>(p.lidar->edge_points.size());
      row.edge_rms_mm = EdgeRmsMm(s.cam_from_lidar, *p.lidar, *p.camera, dataset.target);
    }
    report.pairs.push_back(std::move(row));
  }
  if (!report_options.cross_validate) {
    report.cross_validation_skipped = "cross-validation was not asked for";
  } else if (solved.size() < 5) {
    report.cross_validation_skipped = "fewer than 5 pairs in the solve";
  } else {
    CrossValidate(dataset, outcome, options, report_options, solved, &report);
  }
  if (report_options.sigma_history) SigmaHistory(outcome, options, solved, &report);
  MarkWorstRows(&report);
  return report;
}

}  // namespace calibench
