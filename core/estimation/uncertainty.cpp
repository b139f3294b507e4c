#include "core/estimation/uncertainty.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/base/names.h"

namespace calibench {
namespace {
constexpr EnumName<TerminationTest> kTerminationTestNames[] = {
    {TerminationTest::kNone, "none"},
    {TerminationTest::kClosedForm, "closed_form"},
    {TerminationTest::kFunctionTolerance, "function_tolerance"},
    {TerminationTest::kGradientTolerance, "gradient_tolerance"},
    {TerminationTest::kParameterTolerance, "parameter_tolerance"},
    {TerminationTest::kLocalMinimum, "local_minimum"},
    {TerminationTest::kIterationCap, "iteration_cap"}};
}  // namespace

std::string TerminationTestName(TerminationTest test) {
  return NameIn(kTerminationTestNames, test);
}

std::optional<TerminationTest> ParseTerminationTest(const std::string& name) {
  return ValueIn(kTerminationTestNames, name);
}

std::string Termination::Describe() const {
  char text[256];
  switch (test) {
    case TerminationTest::kNone:
      return "NOT converged: not solved";
    case TerminationTest::kClosedForm:
      return "closed form (nothing to iterate)";
    case TerminationTest::kFunctionTolerance:
      std::snprintf(text, sizeof(text),
                    "converged: relative cost change %.1e <= %.0e (function tolerance)", value,
                    tolerance);
      return text;
    case TerminationTest::kGradientTolerance:
      std::snprintf(text, sizeof(text), "converged: gradient %.1e <= %.0e (gradient tolerance)",
                    value, tolerance);
      return text;
    case TerminationTest::kParameterTolerance:
      std::snprintf(text, sizeof(text),
                    "converged: relative step %.1e <= %.0e (parameter tolerance)", value,
                    tolerance);
      return text;
    case TerminationTest::kLocalMinimum:
      std::snprintf(text, sizeof(text),
                    "converged: no step lowers the cost, neither Gauss-Newton's (its linearization "
                    "predicted %.1e of the cost) nor 0.01 or 0.1 sigma along any parameter: a "
                    "local minimum",
                    value);
      return text;
    case TerminationTest::kIterationCap:
      std::snprintf(text, sizeof(text),
                    "NOT converged: stopped at the iteration cap (%d) with the cost still "
                    "changing by %.1e of itself per iteration (> %.0e)",
                    cap, value, tolerance);
      return text;
  }
  return "";
}

ObservabilityReport AnalyseObservability(const Mat6& information, const Pose& cam_from_lidar,
                                         double weak_eigenvalue_ratio, const std::string& sensor) {
  ObservabilityReport report;
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(information);
  report.eigenvalues = eigen.eigenvalues();
  const double largest = std::max(report.eigenvalues[5], 1e-300);
  int num_weak = 0;
  while (num_weak < 6 && report.eigenvalues[num_weak] < weak_eigenvalue_ratio * largest) ++num_weak;
  if (num_weak == 0) {
    report.well_constrained = true;
    return report;
  }
  // Weak eigenvalues are often (nearly) repeated, so single eigenvectors are arbitrary mixtures.
  // Name instead each camera-frame axis motion that lies mostly inside the weak subspace; the
  // perturbation acts on the right, so a camera-frame direction a is rho (or phi) = Rᵀ a.
  const Eigen::MatrixXd weak_basis = eigen.eigenvectors().leftCols(num_weak);
  const Mat3& rotation = cam_from_lidar.linear();
  static const char* kAxisNames[3] = {"x (right)", "y (down)", "z (forward)"};
  for (int kind = 0; kind < 2; ++kind) {
    for (int axis = 0; axis < 3; ++axis) {
      Vec6 motion = Vec6::Zero();
      motion.segment<3>(3 * kind) = rotation.transpose() * Vec3::Unit(axis);
      if ((weak_basis.transpose() * motion).squaredNorm() < 0.5) continue;
      report.weak_directions.push_back(
          std::string(kind == 0 ? "translation along camera " : "rotation about camera ") +
          kAxisNames[axis] + (kind == 1 ? " through the " + sensor + " origin" : ""));
    }
  }
  for (int i = 0; i < num_weak && report.weak_directions.size() < static_cast<size_t>(num_weak);
       ++i) {
    // A weak direction that is no single axis: describe the eigenvector itself.
    const Vec6 v = eigen.eigenvectors().col(i);
    const Vec3 t = rotation * v.head<3>();
    const Vec3 r = rotation * v.tail<3>();
    char text[160];
    std::snprintf(text, sizeof(text),
                  "combined motion: translation [%.2f, %.2f, %.2f] with rotation [%.2f, %.2f, "
                  "%.2f] (camera frame, eigenvalue ratio %.1e)",
                  t.x(), t.y(), t.z(), r.x(), r.y(), r.z(), report.eigenvalues[i] / largest);
    report.weak_directions.push_back(text);
  }
  report.well_constrained = false;
  return report;
}

Vec3 TranslationStd(const Mat6& covariance, const Pose& cam_from_lidar) {
  const Mat3& r = cam_from_lidar.linear();
  const Mat3 in_cam = r * covariance.topLeftCorner<3, 3>() * r.transpose();
  return in_cam.diagonal().cwiseMax(0.0).cwiseSqrt();
}

Vec3 RotationStdDeg(const Mat6& covariance, const Pose& cam_from_lidar) {
  const Mat3& r = cam_from_lidar.linear();
  const Mat3 in_cam = r * covariance.bottomRightCorner<3, 3>() * r.transpose();
  return in_cam.diagonal().cwiseMax(0.0).cwiseSqrt() * kRadToDeg;
}

}  // namespace calibench
