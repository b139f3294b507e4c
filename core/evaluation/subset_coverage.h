// Is the reported σ honest? The subset protocol on one dataset: calibrate its first k pairs (the
// order a capture adds them) and random subsets of k pairs, and ask whether each result lies
// within a few of its own σ (per axis) of the all-pairs result, and, where the dataset has a ground
// truth (a simulated set), of the truth. The all-pairs result shares pairs with every subset, so at
// large k it flatters σ; the truth does not. Features are extracted once; each
// subset is solved as `calibrate --pairs` would solve it from those features.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"

namespace calibench {

struct SubsetCoverageOptions {
  std::vector<int> first_k{4, 6, 8, 10, 15, 20, 30};  // prefixes of the dataset's pair order
  std::vector<int> random_sizes{4, 6, 8, 10, 15, 20, 30};
  int random_subsets = 5;        // per size in random_sizes
  double coverage_sigmas = 3.0;  // a case is covered when every axis is within this many σ
  std::uint64_t seed = 1;        // random subsets
  bool Check(std::string* why) const;
};

// One subset's result against the all-pairs result. Errors and σ in the camera frame: the
// translation difference, and the rotation difference Log(R_subset R_allᵀ) (the right
// perturbation's covariance rotated into the camera frame, as TranslationStd / RotationStdDeg).
struct SubsetCase {
  std::string kind;  // "first" or "random"
  int k = 0;         // pairs asked for
  int used = 0;      // of them accepted and solved with
  bool solved = false;
  std::string failure;
  Vec3 translation_error_m = Vec3::Zero();
  Vec3 rotation_error_deg = Vec3::Zero();
  Vec3 sigma_t_m = Vec3::Zero();
  Vec3 sigma_r_deg = Vec3::Zero();
  double worst_ratio = 0.0;  // max over the six axes of |error| / σ
  bool covered = false;      // worst_ratio <= coverage_sigmas
  // The same against the ground truth, where there is one.
  Vec3 truth_translation_error_m = Vec3::Zero();
  Vec3 truth_rotation_error_deg = Vec3::Zero();
  double truth_worst_ratio = 0.0;
  bool truth_covered = false;
};

struct SubsetCoverage {
  SolverResult reference;  // all accepted pairs
  int reference_pairs = 0;
  std::vector<SubsetCase> cases;
  int solved = 0;
  int covered = 0;
  bool has_truth = false;
  int truth_covered = 0;  // cases within coverage_sigmas of the ground truth
};

// `features`: every pair of the dataset in its order (as CalibrateDataset returns them); only the
// accepted ones are solved with. `cam_from_lidar_truth`: the dataset's ground truth, if any.
// Throws std::invalid_argument for options that fail Check and std::runtime_error when the
// all-pairs solve fails.
SubsetCoverage RunSubsetCoverage(const std::vector<PairFeatures>& features,
                                 const PipelineOptions& options,
                                 const SubsetCoverageOptions& coverage_options,
                                 const std::optional<Pose>& cam_from_lidar_truth = std::nullopt);

// Markdown: one row per case, then the coverage.
std::string FormatSubsetCoverage(const SubsetCoverage& coverage, double coverage_sigmas);

}  // namespace calibench
