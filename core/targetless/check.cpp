#include "core/targetless/check.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/geometry/geometry.h"

namespace calibench {
namespace {

constexpr double kRefine = -1.0;  // AlignEdges' first radius: the final level only

bool IsTranslation(int axis) { return axis < 3; }

// Per-axis scale: metres for translation axes, radians for rotation axes.
Vec6 Tolerances(const CheckOptions& options) {
  Vec6 tol;
  tol << Vec3::Constant(options.tolerance_m), Vec3::Constant(options.tolerance_deg * kDegToRad);
  return tol;
}

// χ² with k degrees of freedom as the equivalent one-sided Gaussian z (Wilson–Hilferty).
double ChiSquareAsSigma(double chi2, int k) {
  if (k <= 0 || !(chi2 > 0)) return 0.0;
  const double a = 2.0 / (9.0 * k);
  return (std::cbrt(chi2 / k) - (1.0 - a)) / std::sqrt(a);
}

// How far independent parts of the evidence disagree beyond their own σ (a Birge ratio): each
// part aligned alone from the estimate, the mean of (δ_part,i - δ_i)² / σ²_part,i over axes and
// parts. The parts are the depth and the reflectivity edges (two sensors' models of an edge that
// differ), and disjoint groups of frames (every K-th). 1 when the model holds; the sandwich is
// scaled by it when larger, as the edges' systematic errors are in it and not in the sandwich.
double ModelDispersion(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                       const Pose& estimate, const CheckOptions& options) {
  double dispersion = 1.0;
  auto disagreement = [&](const std::vector<EdgeAlignment>& parts, const Pose& centre) {
    double sum = 0.0;
    int terms = 0;
    for (const EdgeAlignment& part : parts) {
      const Vec6 d = DeltaOnCameraAxes(centre, part.cam_from_lidar);
      for (int i = 0; i < 6; ++i) {
        if (!(part.covariance(i, i) > 0)) continue;
        sum += d(i) * d(i) / part.covariance(i, i);
        ++terms;
      }
    }
    return terms > 0 ? sum / terms : 1.0;
  };
  auto usable = [&](const EdgeAlignment& a) {
    return a.points_matched >= options.min_matched_edges / 2 && a.clusters > 6 &&
           a.covariance.allFinite() && !a.covariance.isZero();
  };
  // Depth against reflectivity edges: two estimates, their mean's spread.
  EdgeAlignmentOptions depth_only = options.alignment, intensity_only = options.alignment;
  depth_only.use_intensity_edges = false;
  intensity_only.use_depth_edges = false;
  const EdgeAlignment depth = AlignEdges(frames, camera, estimate, depth_only, kRefine);
  const EdgeAlignment intensity = AlignEdges(frames, camera, estimate, intensity_only, kRefine);
  if (usable(depth) && usable(intensity)) {
    // Each part's deviation from the other, over the sum of their variances.
    Vec6 d = DeltaOnCameraAxes(depth.cam_from_lidar, intensity.cam_from_lidar);
    double sum = 0.0;
    for (int i = 0; i < 6; ++i)
      sum += d(i) * d(i) / (depth.covariance(i, i) + intensity.covariance(i, i));
    dispersion = std::max(dispersion, sum / 6.0);
  }
  const int groups = std::min<int>(4, static_cast<int>(frames.size()) / 2);
  if (groups >= 2) {
    std::vector<EdgeAlignment> parts;
    for (int g = 0; g < groups; ++g) {
      std::vector<EdgeFrame> subset;
      for (size_t f = g; f < frames.size(); f += groups) subset.push_back(frames[f]);
      EdgeAlignment a = AlignEdges(subset, camera, estimate, options.alignment, kRefine);
      if (usable(a)) parts.push_back(std::move(a));
    }
    if (parts.size() >= 2)
      dispersion =
          std::max(dispersion, disagreement(parts, estimate) * parts.size() / (parts.size() - 1.0));
  }
  return dispersion;
}

void WeakestProfile(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                    const CheckOptions& options, CheckReport* report) {
  const Vec6 tol = Tolerances(options);
  const Mat6 scaled =
      tol.cwiseInverse().asDiagonal() * report->covariance * tol.cwiseInverse().asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(scaled);
  const Vec6 v = eigen.eigenvectors().col(5);  // largest variance per tolerance
  report->weakest_direction = v;
  for (int k = -8; k <= 8; ++k) {
    const double s = 0.25 * k;
    const Vec6 delta = s * tol.cwiseProduct(v);
    report->weakest_offsets.push_back(s);
    report->weakest_costs.push_back(AlignmentCost(
        frames, camera, PerturbOnCameraAxes(report->estimate, delta), options.alignment));
  }
}

std::string Fmt(const char* format, double a, double b = 0, double c = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, format, a, b, c);
  return buffer;
}

std::string AxesList(const std::vector<int>& axes) {
  std::string out;
  for (size_t i = 0; i < axes.size(); ++i) {
    if (i > 0) out += i + 1 == axes.size() ? " and " : ", ";
    out += CameraAxisName(axes[i]);
  }
  return out;
}

void Decide(const CheckOptions& options, const Mat6& reference_covariance, CheckReport* report) {
  const Vec6 tol = Tolerances(options);
  const Vec6 delta = DeltaOnCameraAxes(report->reference, report->estimate);
  std::vector<int> constrained;
  for (int i = 0; i < 6; ++i) {
    if (std::sqrt(report->covariance(i, i)) <= 0.5 * tol(i))
      constrained.push_back(i);
    else
      report->unconstrained_axes.push_back(i);
  }
  const Mat6 test = report->covariance + reference_covariance;
  const int k = static_cast<int>(constrained.size());
  Eigen::MatrixXd sub(k, k);
  Eigen::VectorXd d(k);
  double rotation_sq = 0.0, translation_sq = 0.0;
  for (int a = 0; a < k; ++a) {
    d(a) = delta(constrained[a]);
    for (int b = 0; b < k; ++b) sub(a, b) = test(constrained[a], constrained[b]);
    (IsTranslation(constrained[a]) ? translation_sq : rotation_sq) += d(a) * d(a);
  }
  const double chi2 = k > 0 ? d.dot(sub.ldlt().solve(d)) : 0.0;
  report->change_sigmas = std::max(0.0, ChiSquareAsSigma(chi2, k));
  const bool significant = report->change_sigmas > options.significance_sigma;
  const bool large = std::sqrt(rotation_sq) > tol(3) || std::sqrt(translation_sq) > tol(0);
  const std::string change =
      Fmt("%.2f deg and %.1f mm", report->change_r_deg.norm(), 1e3 * report->change_t_m.norm());
  const std::string evidence =
      Fmt("%.0f frames, %.0f matched edge points in %.0f image cells", report->frames_used,
          report->alignment.points_matched, report->alignment.clusters);
  if (significant && large && options.reference_is_guess) {
    // A guess was never a calibration: what the scene supports refines it.
    report->verdict = CheckVerdict::kRefined;
    report->why = "the guess refined: the scene's edges align " + change + " away from it (" +
                  Fmt("%.1f", report->change_sigmas) + " sigma over the constrained axes; " +
                  evidence + "); the estimate below is the refined calibration";
    if (!report->unconstrained_axes.empty())
      report->why += ", though this scene cannot tell the " + AxesList(report->unconstrained_axes) +
                     ", which keep the guess's values";
  } else if (significant && large) {
    report->verdict = CheckVerdict::kMiscalibrated;
    report->why = "the scene's edges align " + change + " away from the calibration (" +
                  Fmt("%.1f", report->change_sigmas) + " sigma over the constrained axes; " +
                  evidence + "); the estimate below is offered as a correction";
    if (!report->unconstrained_axes.empty())
      report->why += ", though this scene cannot tell the " + AxesList(report->unconstrained_axes) +
                     ", which keep the calibration's values";
  } else if (report->unconstrained_axes.empty()) {
    report->verdict = CheckVerdict::kConsistent;
    report->why = "the scene's edges agree with the calibration: the best alignment lies " +
                  change + " from it, " +
                  (significant ? "a change below the tolerance ("
                               : "within the sigma of both and the tolerance (") +
                  Fmt("%.2f deg / %.0f mm; ", options.tolerance_deg, 1e3 * options.tolerance_m) +
                  evidence + ")";
  } else {
    report->verdict = CheckVerdict::kCannotTell;
    report->why = "this scene cannot tell the " + AxesList(report->unconstrained_axes) +
                  " to the tolerance (" +
                  Fmt("%.2f deg / %.0f mm", options.tolerance_deg, 1e3 * options.tolerance_m) +
                  "): its edges do not constrain " +
                  (report->unconstrained_axes.size() > 1 ? "them" : "it") +
                  (report->unconstrained_axes.size() == 6
                       ? std::string()
                       : std::string("; the other axes ") +
                             (significant ? "moved by " + change : "agree with it")) +
                  " (" + evidence +
                  "). A scene with edges at several depths and in several directions "
                  "(near objects, vertical and horizontal structure) can tell";
  }
}

// A local alignment comes back only from a fraction of a degree in a scene of large plain
// surfaces (beyond that its nearest edges are the wrong ones). So rotations about R on a grid of a
// quarter of the search window (±half of it per axis, 125 points) are scored by the robust cost
// at a matching radius of 3x the final one; around each of the best few, a grid of half that step
// picks the start. The scene's own answer is then found wherever in the window it lies.
std::vector<Pose> RotationGridStarts(const std::vector<EdgeFrame>& sample,
                                     const CameraModel& camera, const Pose& reference,
                                     const CheckOptions& options) {
  constexpr int kKeep = 4;
  const double step = 0.25 * options.alignment.search_deg * kDegToRad;
  const double radius = 3.0 * options.alignment.final_radius_px;
  auto cost_at = [&](const Vec3& rotation) {
    Vec6 delta = Vec6::Zero();
    delta.tail<3>() = rotation;
    return AlignmentCost(sample, camera, PerturbOnCameraAxes(reference, delta), options.alignment,
                         radius);
  };
  // The 3x3x3 (steps 1) or 5x5x5 (steps 2) grid about `centre`, best first.
  auto grid = [&](const Vec3& centre, double spacing, int steps) {
    std::vector<std::pair<double, Vec3>> scored;
    for (int i = -steps; i <= steps; ++i)
      for (int j = -steps; j <= steps; ++j)
        for (int k = -steps; k <= steps; ++k) {
          const Vec3 rotation = centre + spacing * Vec3(i, j, k);
          scored.push_back({cost_at(rotation), rotation});
        }
    std::sort(scored.begin(), scored.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    return scored;
  };
  std::vector<Pose> starts;
  std::vector<Vec3> kept;
  for (const auto& [cost, coarse] : grid(Vec3::Zero(), step, 2)) {
    if (static_cast<int>(kept.size()) == kKeep) break;
    bool seen = false;
    for (const Vec3& k : kept) seen = seen || (k - coarse).norm() < 0.5 * step;
    if (seen) continue;
    const Vec3 fine = grid(coarse, 0.5 * step, 1).front().second;
    kept.push_back(coarse);
    Vec6 delta = Vec6::Zero();
    delta.tail<3>() = fine;
    starts.push_back(PerturbOnCameraAxes(reference, delta));
  }
  return starts;
}

// Edges align at more than one pose (a checkerboard, rows of lamps): aligned from R and from R
// turned by half the search window about each camera axis either way, on a sample of at most 10
// frames; the start whose alignment costs least is then aligned on every frame, from a radius of
// 4x the final one.
EdgeAlignment BestAlignment(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                            const Pose& reference, const CheckOptions& options,
                            std::vector<Pose>* minima) {
  std::vector<EdgeFrame> sample;
  const size_t every = (frames.size() + 9) / 10;
  for (size_t f = 0; f < frames.size(); f += every) sample.push_back(frames[f]);
  std::vector<Pose> starts = {reference};
  const double turn = 0.5 * options.alignment.search_deg * kDegToRad;
  for (int axis = 3; axis < 6 && turn > 0; ++axis) {
    for (const double sign : {-1.0, 1.0}) {
      Vec6 delta = Vec6::Zero();
      delta(axis) = sign * turn;
      starts.push_back(PerturbOnCameraAxes(reference, delta));
    }
  }
  for (const Pose& p : RotationGridStarts(sample, camera, reference, options)) starts.push_back(p);
  Pose best = reference;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Pose& start : starts) {
    // The prior stays about R, whichever start.
    const EdgeAlignment a = AlignEdges(sample, camera, start, options.alignment, 0.0, &reference);
    const double cost = AlignmentCost(sample, camera, a.cam_from_lidar, options.alignment);
    if (cost < best_cost) best_cost = cost, best = a.cam_from_lidar;
    minima->push_back(a.cam_from_lidar);
  }
  return AlignEdges(frames, camera, best, options.alignment,
                    4.0 * options.alignment.final_radius_px, &reference);
}

// P(X >= k) for X ~ Binomial(n, 1/2): the sign test's one-sided level.
double BinomialUpperTail(int k, int n) {
  double p = 0.0;
  for (int i = std::max(k, 0); i <= n; ++i)
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) -
                  n * std::log(2.0));
  return std::min(1.0, p);
}

// Student's t, one-sided 99 %, by degrees of freedom (1..30; beyond, the normal's 2.33).
double StudentT99(int dof) {
  static constexpr double kTable[] = {31.82, 6.965, 4.541, 3.747, 3.365, 3.143, 2.998, 2.896,
                                      2.821, 2.764, 2.718, 2.681, 2.650, 2.624, 2.602, 2.583,
                                      2.567, 2.552, 2.539, 2.528, 2.518, 2.508, 2.500, 2.492,
                                      2.485, 2.479, 2.473, 2.467, 2.462, 2.457};
  return dof >= 1 && dof <= 30 ? kTable[dof - 1] : 2.326;
}

// Edges can fit more than one alignment about equally well (a box's silhouette beside the shading
// edge of its own corner, rows of posters, a 16-beam LiDAR's 2° between rings): the local
// curvature then says nothing of the other fit, and the sandwich σ is far too small. Every other
// minimum the starts found, farther than 3σ from the estimate, is put to a paired test over the
// frames (each frame an independent look at the scene, whatever σ says): the estimate's cost must
// be lower by more than the frames' own spread of the difference allows by chance (Student's t,
// one-sided, 1 %), or lower in significantly more frames than not (sign test, one-sided, 5 %). A
// rival that survives widens the covariance by its offset, so the axes it moves along are not
// called constrained. One frame cannot be tested against itself: no rival then.
void AddRivalMinima(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                    const std::vector<Pose>& minima, const CheckOptions& options,
                    CheckReport* report) {
  const int n = static_cast<int>(frames.size());
  if (n < 2) return;
  const std::vector<double> best =
      AlignmentCostPerFrame(frames, camera, report->estimate, options.alignment);
  const Eigen::LDLT<Mat6> covariance = report->covariance.ldlt();
  for (const Pose& m : minima) {
    const Vec6 d = DeltaOnCameraAxes(report->estimate, m);
    if (d.dot(covariance.solve(d)) < 9.0) continue;  // the same minimum
    bool known = false;
    for (const Vec6& r : report->rival_offsets)
      known = known || (r - d).tail<3>().norm() < 0.05 * kDegToRad;
    if (known) continue;
    const std::vector<double> other = AlignmentCostPerFrame(frames, camera, m, options.alignment);
    double sum = 0.0, sum_sq = 0.0;
    int wins = 0, decided = 0;
    for (int f = 0; f < n; ++f) {
      const double gain = other[f] - best[f];
      sum += gain;
      sum_sq += gain * gain;
      decided += gain != 0.0;
      wins += gain > 0.0;
    }
    const double mean = sum / n, var = std::max(0.0, (sum_sq - n * mean * mean) / (n - 1));
    const bool t_test = mean > 0.0 && (var == 0.0 || mean / std::sqrt(var / n) > StudentT99(n - 1));
    // A few frames with large differences can hide a consistent preference from the t test.
    const bool sign_test = BinomialUpperTail(wins, decided) < 0.05;
    if (t_test || sign_test) continue;
    report->rival_offsets.push_back(d);
    report->rival_frames_preferring.push_back(decided - wins);
    report->rival_frames_decided.push_back(decided);
  }
  for (const Vec6& d : report->rival_offsets) report->covariance += d * d.transpose();
}

// The rival alignments in one sentence: one named as it is, several by their range (the largest
// offset first: it is what widened the sigma most).
std::string DescribeRivals(const CheckReport& report) {
  const size_t n = report.rival_offsets.size();
  if (n == 0) return "";
  auto degrees = [&](size_t r) { return report.rival_offsets[r].tail<3>().norm() * kRadToDeg; };
  auto millimetres = [&](size_t r) { return 1e3 * report.rival_offsets[r].head<3>().norm(); };
  if (n == 1)
    return Fmt(". The edges also fit an alignment %.2f deg / %.1f mm from the estimate about as "
               "well",
               degrees(0), millimetres(0)) +
           Fmt(" (better in %.0f of %.0f frames); its offset is counted in the sigma",
               report.rival_frames_preferring[0], report.rival_frames_decided[0]);
  double min_deg = 1e9, max_deg = 0, min_mm = 1e9, max_mm = 0;
  int most_preferring = 0, decided = 0;
  for (size_t r = 0; r < n; ++r) {
    min_deg = std::min(min_deg, degrees(r));
    max_deg = std::max(max_deg, degrees(r));
    min_mm = std::min(min_mm, millimetres(r));
    max_mm = std::max(max_mm, millimetres(r));
    most_preferring = std::max(most_preferring, report.rival_frames_preferring[r]);
    decided = std::max(decided, report.rival_frames_decided[r]);
  }
  return Fmt(". The edges also fit %.0f other alignments about as well, ", n) +
         Fmt("%.2f-%.2f deg / ", min_deg, max_deg) +
         Fmt("%.1f-%.1f mm from the estimate", min_mm, max_mm) +
         Fmt(" (each better in at most %.0f of %.0f frames): the scene has several answers "
             "nearly as good, and their offsets are counted in the sigma",
             most_preferring, decided);
}

}  // namespace

bool CheckOptions::Check(std::string* why) const {
  if (!lidar_edges.Check(why) || !image_edges.Check(why) || !alignment.Check(why)) return false;
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(tolerance_deg > 0) || !(tolerance_m > 0))
    return fail("the check's tolerances must be > 0 degrees and > 0 m");
  if (!(significance_sigma > 0)) return fail("the check's significance must be > 0 sigma");
  if (min_matched_edges < 12 || min_clusters < 7 || min_frame_matches < 1)
    return fail("the check needs at least 12 matched edges in 7 image cells");
  return true;
}

std::string CheckVerdictName(CheckVerdict verdict) {
  switch (verdict) {
    case CheckVerdict::kConsistent:
      return "consistent";
    case CheckVerdict::kMiscalibrated:
      return "miscalibrated";
    case CheckVerdict::kCannotTell:
      return "cannot tell";
    case CheckVerdict::kRefined:
      return "refined";
  }
  return "cannot tell";
}

std::string CameraAxisName(int axis) {
  static const char* const kNames[6] = {"translation along camera x (right)",
                                        "translation along camera y (down)",
                                        "translation along camera z (forward, depth)",
                                        "rotation about camera x (pitch)",
                                        "rotation about camera y (yaw)",
                                        "rotation about camera z (roll)"};
  return axis >= 0 && axis < 6 ? kNames[axis] : "?";
}

EdgeFrame MakeEdgeFrame(const std::string& id, const LidarCloud& cloud, const ImageU8& image,
                        const CheckOptions& options) {
  return EdgeFrame{id, ExtractLidarEdges(cloud, options.lidar_edges),
                   DetectImageEdges(image, options.image_edges)};
}

Mat6 CameraAxesCovariance(const Mat6& right_covariance, const Pose& cam_from_lidar) {
  Mat6 m = Mat6::Zero();
  m.topLeftCorner<3, 3>() = cam_from_lidar.linear();
  m.bottomRightCorner<3, 3>() = cam_from_lidar.linear();
  return m * right_covariance * m.transpose();
}

Mat6 RightPerturbationCovariance(const Mat6& camera_axes_covariance, const Pose& cam_from_lidar) {
  Mat6 m = Mat6::Zero();
  m.topLeftCorner<3, 3>() = cam_from_lidar.linear().transpose();
  m.bottomRightCorner<3, 3>() = cam_from_lidar.linear().transpose();
  return m * camera_axes_covariance * m.transpose();
}

CheckReport CheckCalibration(const std::vector<EdgeFrame>& frames, const CameraModel& camera,
                             const Pose& reference, const Mat6& reference_covariance,
                             const CheckOptions& options) {
  CheckReport report;
  report.reference = reference;
  report.reference_is_guess = options.reference_is_guess;
  report.frames_given = static_cast<int>(frames.size());
  for (const EdgeFrame& f : frames) {
    report.frame_ids.push_back(f.id);
    report.lidar_edges_per_frame.push_back(static_cast<int>(f.lidar_edges.size()));
  }
  std::vector<Pose> minima;
  report.alignment = BestAlignment(frames, camera, reference, options, &minima);
  const EdgeAlignment& a = report.alignment;
  for (int m : a.matched_per_frame) report.frames_used += m >= options.min_frame_matches;
  if (a.points_matched < options.min_matched_edges || a.clusters < options.min_clusters ||
      !a.covariance.allFinite() || a.covariance.isZero()) {
    report.verdict = CheckVerdict::kCannotTell;
    report.why = Fmt("too few edges both sensors see: %.0f LiDAR edge points matched an image "
                     "edge, in %.0f image cells",
                     a.points_matched, a.clusters) +
                 Fmt(" (at least %.0f in %.0f cells are needed); no estimate is offered. Point "
                     "the rig at a scene with objects at several depths",
                     options.min_matched_edges, options.min_clusters);
    for (int i = 0; i < 6; ++i) report.unconstrained_axes.push_back(i);
    return report;
  }
  report.has_estimate = true;
  report.estimate = a.cam_from_lidar;
  report.model_dispersion = ModelDispersion(frames, camera, report.estimate, options);
  report.covariance = report.model_dispersion * a.covariance;
  AddRivalMinima(frames, camera, minima, options, &report);
  report.sigma_t_m = report.covariance.diagonal().head<3>().cwiseSqrt();
  report.sigma_r_deg = report.covariance.diagonal().tail<3>().cwiseSqrt() * kRadToDeg;
  const Vec6 delta = DeltaOnCameraAxes(reference, report.estimate);
  report.change_t_m = delta.head<3>();
  report.change_r_deg = delta.tail<3>() * kRadToDeg;
  Decide(options, reference_covariance, &report);
  report.why += DescribeRivals(report);
  WeakestProfile(frames, camera, options, &report);
  return report;
}

}  // namespace calibench
