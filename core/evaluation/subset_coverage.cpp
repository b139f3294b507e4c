#include "core/evaluation/subset_coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <stdexcept>

#include "core/estimation/uncertainty.h"

namespace calibench {

bool SubsetCoverageOptions::Check(std::string* why) const {
  for (int k : first_k)
    if (k < 3) return *why = "subset sizes must be >= 3 (planes fix the pose from 3 pairs)", false;
  for (int k : random_sizes)
    if (k < 3) return *why = "subset sizes must be >= 3 (planes fix the pose from 3 pairs)", false;
  if (random_subsets < 0) return *why = "random_subsets must be >= 0", false;
  if (!(coverage_sigmas > 0)) return *why = "coverage_sigmas must be > 0", false;
  return true;
}

namespace {

// The largest |error| / σ over the six axes of `solved` against `reference`, with the errors.
double WorstRatio(const SolverResult& solved, const Pose& reference, const Vec3& sigma_t_m,
                  const Vec3& sigma_r_deg, Vec3* translation_error_m, Vec3* rotation_error_deg) {
  *translation_error_m = solved.cam_from_lidar.translation() - reference.translation();
  *rotation_error_deg =
      LogSO3(solved.cam_from_lidar.linear() * reference.linear().transpose()) * kRadToDeg;
  double worst = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    worst =
        std::max(worst, std::abs((*translation_error_m)[axis]) / std::max(sigma_t_m[axis], 1e-12));
    worst =
        std::max(worst, std::abs((*rotation_error_deg)[axis]) / std::max(sigma_r_deg[axis], 1e-12));
  }
  return worst;
}

SubsetCase SolveCase(const std::string& kind, int k, std::vector<PairFeatures> subset,
                     const PipelineOptions& options, const Pose& reference,
                     const std::optional<Pose>& truth, double coverage_sigmas) {
  SubsetCase c;
  c.kind = kind;
  c.k = k;
  for (const PairFeatures& p : subset) c.used += p.status == PairStatus::kAccepted;
  const CalibrationOutcome outcome = SolveFromFeatures(std::move(subset), options);
  if (!outcome.solution) {
    c.failure = outcome.failure;
    return c;
  }
  const SolverResult& s = *outcome.solution;
  c.solved = true;
  c.sigma_t_m = TranslationStd(s.covariance, s.cam_from_lidar);
  c.sigma_r_deg = RotationStdDeg(s.covariance, s.cam_from_lidar);
  c.worst_ratio = WorstRatio(s, reference, c.sigma_t_m, c.sigma_r_deg, &c.translation_error_m,
                             &c.rotation_error_deg);
  c.covered = c.worst_ratio <= coverage_sigmas;
  if (truth) {
    c.truth_worst_ratio = WorstRatio(s, *truth, c.sigma_t_m, c.sigma_r_deg,
                                     &c.truth_translation_error_m, &c.truth_rotation_error_deg);
    c.truth_covered = c.truth_worst_ratio <= coverage_sigmas;
  }
  return c;
}

}  // namespace

SubsetCoverage RunSubsetCoverage(const std::vector<PairFeatures>& features,
                                 const PipelineOptions& options,
                                 const SubsetCoverageOptions& coverage_options,
                                 const std::optional<Pose>& cam_from_lidar_truth) {
  std::string why;
  if (!coverage_options.Check(&why)) throw std::invalid_argument(why);
  SubsetCoverage coverage;
  const CalibrationOutcome all = SolveFromFeatures(features, options);
  if (!all.solution) throw std::runtime_error("the all-pairs solve failed: " + all.failure);
  coverage.reference = *all.solution;
  for (const PairFeatures& p : features)
    coverage.reference_pairs += p.status == PairStatus::kAccepted;
  const Pose& reference = coverage.reference.cam_from_lidar;
  const int n = static_cast<int>(features.size());
  for (int k : coverage_options.first_k) {
    if (k >= n) continue;
    coverage.cases.push_back(
        SolveCase("first", k, std::vector<PairFeatures>(features.begin(), features.begin() + k),
                  options, reference, cam_from_lidar_truth, coverage_options.coverage_sigmas));
  }
  std::vector<int> accepted;
  for (int i = 0; i < n; ++i)
    if (features[i].status == PairStatus::kAccepted) accepted.push_back(i);
  std::mt19937_64 rng(coverage_options.seed);
  for (int k : coverage_options.random_sizes) {
    if (k >= static_cast<int>(accepted.size())) continue;
    for (int s = 0; s < coverage_options.random_subsets; ++s) {
      std::vector<int> order = accepted;
      std::shuffle(order.begin(), order.end(), rng);
      order.resize(k);
      std::sort(order.begin(), order.end());
      std::vector<PairFeatures> subset;
      for (int i : order) subset.push_back(features[i]);
      coverage.cases.push_back(SolveCase("random", k, std::move(subset), options, reference,
                                         cam_from_lidar_truth, coverage_options.coverage_sigmas));
    }
  }
  coverage.has_truth = cam_from_lidar_truth.has_value();
  for (const SubsetCase& c : coverage.cases) {
    coverage.solved += c.solved;
    coverage.covered += c.covered;
    coverage.truth_covered += c.truth_covered;
  }
  return coverage;
}

std::string FormatSubsetCoverage(const SubsetCoverage& coverage, double coverage_sigmas) {
  const bool truth = coverage.has_truth;
  std::string out =
      "| subset | k | used | largest σ_t (mm) | largest σ_r (deg) | distance to all pairs "
      "(mm / deg) | worst axis (σ) | covered |";
  out += truth ? " to the truth (mm / deg) | worst axis (σ) | covered |\n" : "\n";
  out += truth ? "|---|---|---|---|---|---|---|---|---|---|---|\n"
               : "|---|---|---|---|---|---|---|---|\n";
  char line[400];
  for (const SubsetCase& c : coverage.cases) {
    if (!c.solved) {
      std::snprintf(line, sizeof(line), "| %s | %d | %d | — | — | no solution: %s | — | no |%s\n",
                    c.kind.c_str(), c.k, c.used, c.failure.c_str(), truth ? " — | — | no |" : "");
      out += line;
      continue;
    }
    std::snprintf(line, sizeof(line), "| %s | %d | %d | %.1f | %.3f | %.1f / %.3f | %.2f | %s |",
                  c.kind.c_str(), c.k, c.used, c.sigma_t_m.maxCoeff() * 1e3,
                  c.sigma_r_deg.maxCoeff(), c.translation_error_m.norm() * 1e3,
                  c.rotation_error_deg.norm(), c.worst_ratio, c.covered ? "yes" : "NO");
    out += line;
    if (truth) {
      std::snprintf(line, sizeof(line), " %.1f / %.3f | %.2f | %s |",
                    c.truth_translation_error_m.norm() * 1e3, c.truth_rotation_error_deg.norm(),
                    c.truth_worst_ratio, c.truth_covered ? "yes" : "NO");
      out += line;
    }
    out += "\n";
  }
  const int cases = static_cast<int>(coverage.cases.size());
  const auto percent = [cases](int n) { return cases ? 100.0 * n / cases : 0.0; };
  std::snprintf(line, sizeof(line),
                "\nwithin %.0fσ on every axis of the all-pairs result: %d of %d cases (%.0f %%); "
                "all-pairs result from %d pairs\n",
                coverage_sigmas, coverage.covered, cases, percent(coverage.covered),
                coverage.reference_pairs);
  out += line;
  if (truth) {
    std::snprintf(line, sizeof(line),
                  "within %.0fσ on every axis of the ground truth: %d of %d cases (%.0f %%)\n",
                  coverage_sigmas, coverage.truth_covered, cases, percent(coverage.truth_covered));
    out += line;
  }
  return out;
}

}  // namespace calibench
