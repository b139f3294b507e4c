#include "core/sim/subset_coverage.h"

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

SubsetCase SolveCase(const std::string& kind, int k, std::vector<PairFeatures> subset,
                     const PipelineOptions& options, const Pose& reference,
                     double coverage_sigmas) {
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
  c.translation_error_m = s.cam_from_lidar.translation() - reference.translation();
  c.rotation_error_deg =
      LogSO3(s.cam_from_lidar.linear() * reference.linear().transpose()) * kRadToDeg;
  c.sigma_t_m = TranslationStd(s.covariance, s.cam_from_lidar);
  c.sigma_r_deg = RotationStdDeg(s.covariance, s.cam_from_lidar);
  for (int axis = 0; axis < 3; ++axis) {
    c.worst_ratio = std::max(
        c.worst_ratio, std::abs(c.translation_error_m[axis]) / std::max(c.sigma_t_m[axis], 1e-12));
    c.worst_ratio = std::max(
        c.worst_ratio, std::abs(c.rotation_error_deg[axis]) / std::max(c.sigma_r_deg[axis], 1e-12));
  }
  c.covered = c.worst_ratio <= coverage_sigmas;
  return c;
}

}  // namespace

SubsetCoverage RunSubsetCoverage(const std::vector<PairFeatures>& features,
                                 const PipelineOptions& options,
                                 const SubsetCoverageOptions& coverage_options) {
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
                  options, reference, coverage_options.coverage_sigmas));
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
                                         coverage_options.coverage_sigmas));
    }
  }
  for (const SubsetCase& c : coverage.cases) {
    coverage.solved += c.solved;
    coverage.covered += c.covered;
  }
  return coverage;
}

std::string FormatSubsetCoverage(const SubsetCoverage& coverage, double coverage_sigmas) {
  std::string out =
      "| subset | k | used | largest σ_t (mm) | largest σ_r (deg) | distance to all pairs "
      "(mm / deg) | worst axis (σ) | covered |\n|---|---|---|---|---|---|---|---|\n";
  char line[320];
  for (const SubsetCase& c : coverage.cases) {
    if (!c.solved) {
      std::snprintf(line, sizeof(line), "| %s | %d | %d | — | — | no solution: %s | — | no |\n",
                    c.kind.c_str(), c.k, c.used, c.failure.c_str());
    } else {
      std::snprintf(line, sizeof(line),
                    "| %s | %d | %d | %.1f | %.3f | %.1f / %.3f | %.2f | %s |\n", c.kind.c_str(),
                    c.k, c.used, c.sigma_t_m.maxCoeff() * 1e3, c.sigma_r_deg.maxCoeff(),
                    c.translation_error_m.norm() * 1e3, c.rotation_error_deg.norm(), c.worst_ratio,
                    c.covered ? "yes" : "NO");
    }
    out += line;
  }
  const int cases = static_cast<int>(coverage.cases.size());
  std::snprintf(line, sizeof(line),
                "\nwithin %.0fσ on every axis: %d of %d cases (%.0f %%); all-pairs result from "
                "%d pairs\n",
                coverage_sigmas, coverage.covered, cases,
                cases ? 100.0 * coverage.covered / cases : 0.0, coverage.reference_pairs);
  out += line;
  return out;
}

}  // namespace calibench
