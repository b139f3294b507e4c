#include <gtest/gtest.h>

#include <random>

#include "core/geometry/geometry.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

using test::MatrixNear;

Vec6 RandomTangent(std::mt19937_64& rng, double translation_scale, double rotation_scale) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec6 xi;
  for (int i = 0; i < 3; ++i) xi[i] = translation_scale * normal(rng);
  for (int i = 3; i < 6; ++i) xi[i] = rotation_scale * normal(rng);
  return xi;
}

Plane RandomPlane(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Vec3 n = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
  return Plane{n, 1.0 + 3.0 * std::abs(normal(rng))};
}

TEST(Geometry, ExpLogRoundTripOnRandomSamples) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 500; ++i) {
    const Vec6 xi = RandomTangent(rng, 2.0, 0.9);
    if (xi.tail<3>().norm() > 3.0) continue;
    EXPECT_TRUE(MatrixNear(LogSE3(ExpSE3(xi)), xi, 1e-9));
  }
  // Tiny angles use the series branch.
  Vec6 tiny;
  tiny << 0.3, -0.2, 0.1, 1e-10, -2e-10, 3e-10;
  EXPECT_TRUE(MatrixNear(LogSE3(ExpSE3(tiny)), tiny, 1e-12));
}

TEST(Geometry, ExpSO3IsARotationAndMatchesEigenAngleAxis) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3 phi = RandomTangent(rng, 0, 1.0).tail<3>();
    const Mat3 r = ExpSO3(phi);
    EXPECT_TRUE(MatrixNear(r * r.transpose(), Mat3::Identity(), 1e-12));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    EXPECT_TRUE(
        MatrixNear(r, Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix(), 1e-12));
  }
}

TEST(Geometry, LeftJacobianMatchesNumericDerivativeOfExp) {
  // Exp(phi + eps) ≈ Exp(J_l(phi) eps) Exp(phi).
  std::mt19937_64 rng(11);
  for (int i = 0; i < 50; ++i) {
    const Vec3 phi = RandomTangent(rng, 0, 0.8).tail<3>();
    const Mat3 jl = LeftJacobianSO3(phi);
    EXPECT_TRUE(MatrixNear(jl * LeftJacobianInverseSO3(phi), Mat3::Identity(), 1e-10));
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      const Vec3 e = Vec3::Unit(k) * h;
      const Vec3 numeric = LogSO3(ExpSO3(phi + e) * ExpSO3(phi).transpose()) / h;
      EXPECT_TRUE(MatrixNear(numeric, jl.col(k), 1e-5));
    }
  }
}

TEST(Geometry, AdjointConjugatesTheExponential) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 100; ++i) {
    const Pose t = ExpSE3(RandomTangent(rng, 1.0, 0.7));
    const Vec6 xi = RandomTangent(rng, 0.3, 0.3);
    const Pose lhs = ExpSE3(AdjointSE3(t) * xi);
    const Pose rhs = t * ExpSE3(xi) * t.inverse();
    EXPECT_TRUE(MatrixNear(lhs.matrix(), rhs.matrix(), 1e-10));
  }
}

TEST(Geometry, TransformPlaneKeepsPointsOnThePlane) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const Plane plane_in_a = RandomPlane(rng);
    const Pose b_from_a = ExpSE3(RandomTangent(rng, 2.0, 1.0));
    const Plane plane_in_b = TransformPlane(b_from_a, plane_in_a);
    EXPECT_NEAR(plane_in_b.normal.norm(), 1.0, 1e-12);
    for (int k = 0; k < 5; ++k) {
      Vec3 x(normal(rng), normal(rng), normal(rng));
      x -= plane_in_a.normal * plane_in_a.SignedDistance(x);  // project onto the plane
      EXPECT_NEAR(plane_in_b.SignedDistance(b_from_a * x), 0.0, 1e-10);
    }
    // Round trip through the inverse.
    const Plane back = TransformPlane(b_from_a.inverse(), plane_in_b);
    EXPECT_TRUE(MatrixNear(back.Coefficients(), plane_in_a.Coefficients(), 1e-10));
  }
}

TEST(Geometry, OrientTowardsOriginGivesPositiveDistance) {
  const Plane p{Vec3(0, 0, 1), -2.0};  // z = 2, normal pointing away from the origin
  const Plane q = OrientTowardsOrigin(p);
  EXPECT_TRUE(MatrixNear(q.normal, Vec3(0, 0, -1), 0));
  EXPECT_DOUBLE_EQ(q.distance, 2.0);
  EXPECT_TRUE(MatrixNear(q.ClosestPointToOrigin(), Vec3(0, 0, 2), 1e-15));
}

TEST(Geometry, PlaneToPlaneErrorIsZeroForIdenticalPlanesAndMeasuresOffsets) {
  const Plane a{Vec3(0, 0, -1), 3.0};
  EXPECT_TRUE(MatrixNear(PlaneToPlaneError(a, a), Vec4::Zero(), 0));
  const Plane b{Vec3(0, 0, -1), 3.25};  // parallel, 0.25 m further
  const Vec4 e = PlaneToPlaneError(a, b);
  EXPECT_TRUE(MatrixNear(e.head<3>(), Vec3::Zero(), 0));
  EXPECT_NEAR(std::abs(e[3]), 0.25, 1e-15);
}

TEST(Geometry, PlaneAlignmentJacobianMatchesNumericDifferences) {
  std::mt19937_64 rng(21);
  for (int i = 0; i < 200; ++i) {
    const Pose cam_from_lidar = ExpSE3(RandomTangent(rng, 0.5, 1.0));
    const Plane lidar_plane = RandomPlane(rng);
    // Camera plane near the transformed one, so residuals are small but non-zero.
    Plane camera_plane =
        TransformPlane(ExpSE3(RandomTangent(rng, 0.05, 0.05)) * cam_from_lidar, lidar_plane);
    Eigen::Matrix<double, 4, 6> analytic;
    PlaneAlignmentResidual(cam_from_lidar, lidar_plane, camera_plane, &analytic);
    Eigen::Matrix<double, 4, 6> numeric;
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      const Vec6 step = Vec6::Unit(k) * h;
      const Vec4 plus =
          PlaneAlignmentResidual(cam_from_lidar * ExpSE3(step), lidar_plane, camera_plane, nullptr);
      const Vec4 minus = PlaneAlignmentResidual(cam_from_lidar * ExpSE3(-step), lidar_plane,
                                                camera_plane, nullptr);
      numeric.col(k) = (plus - minus) / (2 * h);
    }
    EXPECT_TRUE(MatrixNear(analytic, numeric, 1e-7)) << "sample " << i;
  }
}

TEST(Geometry, NearestRotationProjectsOntoSO3) {
  std::mt19937_64 rng(2);
  const Mat3 r = ExpSO3(RandomTangent(rng, 0, 1.0).tail<3>());
  Mat3 noisy = r;
  noisy(0, 1) += 1e-3;
  const Mat3 projected = NearestRotation(noisy);
  EXPECT_NEAR(projected.determinant(), 1.0, 1e-12);
  EXPECT_LT(RotationAngle(projected, r), 1e-3);
  EXPECT_TRUE(MatrixNear(NearestRotation(r), r, 1e-12));
}

}  // namespace
}  // namespace calibench
