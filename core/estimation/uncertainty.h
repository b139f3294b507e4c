// What every estimator reports besides its estimate: the iterations, the observability of the six
// degrees of freedom, and standard deviations in the camera's axes. Shared by both methods.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench {

struct IterationReport {
  int iteration = 0;       // 0 = the initial estimate
  double cost = 0.0;       // sum of Huber costs, Eq. (14)
  double step_norm = 0.0;  // |delta|
  Pose cam_from_lidar = Pose::Identity();
  double range_offset_m = 0.0;  // SolverOptions::estimate_range_offset
  // The weights changed at this iteration (outliers gated, variance factors re-estimated): its
  // cost is the one under the new weights, not comparable with the costs before it.
  bool reweighted = false;
};

// Which test ended an iterative solve (Ceres's tests: function, gradient and parameter tolerance),
// or the iteration cap, a safety net that means the solve did not converge.
enum class TerminationTest {
  kNone,                // still running, or never run
  kClosedForm,          // nothing to iterate (the estimate is a closed form)
  kFunctionTolerance,   // |Δcost| / cost of the last step within function_tolerance
  kGradientTolerance,   // max |gradient| within gradient_tolerance
  kParameterTolerance,  // |Δx| within parameter_tolerance · (|x| + parameter_tolerance)
  kLocalMinimum,        // no step lowers the cost: Gauss-Newton's nor small moves per parameter
  kIterationCap,        // max_iterations reached with the cost still falling
};
std::string TerminationTestName(TerminationTest test);  // "function_tolerance", ...
std::optional<TerminationTest> ParseTerminationTest(const std::string& name);

struct Termination {
  TerminationTest test = TerminationTest::kNone;
  double value = 0.0;      // what the test measured (for the cap: the last relative cost change)
  double tolerance = 0.0;  // what it was held to (for the cap: the function tolerance)
  int cap = 0;             // kIterationCap: the cap
  bool Converged() const {
    return test != TerminationTest::kNone && test != TerminationTest::kIterationCap;
  }
  // In words: "converged: relative cost change 2.1e-09 <= 1e-06 (function tolerance)", or
  // "NOT converged: ...".
  std::string Describe() const;
  bool operator==(const Termination&) const = default;
};

struct ObservabilityReport {
  Vec6 eigenvalues = Vec6::Zero();           // of the information matrix JᵀWJ, ascending
  std::vector<std::string> weak_directions;  // in words, camera frame
  bool well_constrained = false;
};

// Observability of cam_from_<sensor> from its information matrix (right perturbation, [rho; phi])
// at an estimate: eigenvalues, and the weak directions named in camera axes (a rotation "through
// the <sensor> origin": "LiDAR", "LRF").
ObservabilityReport AnalyseObservability(const Mat6& information, const Pose& cam_from_lidar,
                                         double weak_eigenvalue_ratio,
                                         const std::string& sensor = "LiDAR");

// Standard deviations of cam_from_lidar along the camera axes, from the covariance of its right
// perturbation: the translation of T·Exp([rho; phi]) moves by R·rho and its rotation by R·phi to
// first order, so both blocks are rotated into the camera frame. Metres and degrees.
Vec3 TranslationStd(const Mat6& covariance, const Pose& cam_from_lidar);
Vec3 RotationStdDeg(const Mat6& covariance, const Pose& cam_from_lidar);

}  // namespace calibench
