#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/lrf/solver.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

constexpr double kDegree = M_PI / 180.0;

// LRF 0.15 m above and 0.1 m behind the camera, LRF x (forward) = camera z, LRF y (left) =
// camera −x, LRF z (up) = camera −y, tilted by a few degrees.
Pose TrueCamFromLrf() {
  Mat3 axes;
  axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Pose cam_from_lrf = Pose::Identity();
  cam_from_lrf.linear() = ExpSO3(Vec3(0.04, -0.03, 0.05)) * axes;
  cam_from_lrf.translation() = Vec3(0.0, -0.15, -0.10);
  return cam_from_lrf;
}

double RotationError(const Pose& a, const Pose& b) { return RotationAngle(a.linear(), b.linear()); }
double TranslationError(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm();
}

Line3 LineOfPlanes(const Plane& a, const Plane& b) {
  Line3 line;
  line.direction = a.normal.cross(b.normal).normalized();
  Mat3 system;
  system << a.normal.transpose(), b.normal.transpose(), line.direction.transpose();
  line.point = system.inverse() * Vec3(-a.distance, -b.distance, 0.0);
  return line;
}

// Total least squares line through 2D points.
Line2 FitLine(const std::vector<Vec2>& points) {
  Vec2 centroid = Vec2::Zero();
  for (const Vec2& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Vec2& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  Line2 line;
  line.normal = eigen.eigenvectors().col(0);
  line.offset = -line.normal.dot(centroid);
  return line;
}

Vec2 Intersect(const Line2& a, const Line2& b) {
  Eigen::Matrix2d system;
  system << a.normal.transpose(), b.normal.transpose();
  return system.inverse() * Vec2(-a.offset, -b.offset);
}

struct Noise {
  double range_m = 0.0;     // σ of scan points along the ray
  double normal_rad = 0.0;  // σ of each axis of a random rotation of each depth plane normal
  double distance_m = 0.0;  // σ of each depth plane's d
};

// Fraction u in (0, 1) at which segment a→b crosses the plane, or −1.
double CrossingFraction(const Plane& plane, const Vec3& a, const Vec3& b) {
  const double da = plane.SignedDistance(a), db = plane.SignedDistance(b);
  return da * db < 0 ? da / (da - db) : -1.0;
}

// A random target pose 1–3 m ahead whose scan crosses AB, AC and AD well inside the segments.
// Returns the scan intersection points F, G, H in the target frame.
Pose RandomTargetPose(const ThreeFaceTarget& target, std::mt19937_64& rng,
                      std::array<Vec3, 3>* fgh) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Pose cam_from_lrf = TrueCamFromLrf();
  const Plane scan_plane_in_cam = TransformPlane(cam_from_lrf, Plane{Vec3::UnitZ(), 0.0});
  Mat3 facing;  // target x = camera x, target y (up) = camera −y, target z = camera −z
  facing << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Vec3 ends[3] = {target.B(), target.C(), target.D()};
  for (int attempt = 0; attempt < 10000; ++attempt) {
    Pose cam_from_target = Pose::Identity();
    cam_from_target.linear() = facing * ExpSO3(Vec3(0, 35 * kDegree * uniform(rng), 0)) *
                               ExpSO3(Vec3(25 * kDegree * uniform(rng), 0, 0)) *
                               ExpSO3(Vec3(0, 0, 20 * kDegree * uniform(rng)));
    const double x = 0.4 * uniform(rng), z = 2.0 + uniform(rng);
    // Height of the scan plane at (x, z), then an offset so the scan crosses the tent's middle.
    const Vec3& n = scan_plane_in_cam.normal;
    const double y_scan = -(scan_plane_in_cam.distance + n.x() * x + n.z() * z) / n.y();
    cam_from_target.translation() = Vec3(x, y_scan + 0.1 * uniform(rng), z);
    const Plane scan_plane = TransformPlane(cam_from_target.inverse(), scan_plane_in_cam);
    bool inside = true;
    for (int j = 0; j < 3; ++j) {
      const double u = CrossingFraction(scan_plane, target.A(), ends[j]);
      inside = inside && u > 0.15 && u < 0.85;
      (*fgh)[j] = target.A() + u * (ends[j] - target.A());
    }
    if (inside) return cam_from_target;
  }
  ADD_FAILURE() << "no target pose found";
  return Pose::Identity();
}

// Scan points (target frame) on each face: base from both outer segments, ABC on F..G, ACD on
// G..H.
std::array<std::vector<Vec3>, 3> FacePointsInTarget(const ThreeFaceTarget& target,
                                                    const std::array<Vec3, 3>& fgh,
                                                    std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.02, 0.98);
  const Vec3 &f = fgh[0], &g = fgh[1], &h = fgh[2];
  std::array<std::vector<Vec3>, 3> faces;
  for (int i = 0; i < 40; ++i) {
    faces[1].push_back(f + unit(rng) * (g - f));
    faces[2].push_back(g + unit(rng) * (h - g));
  }
  const Vec3 along = (h - f).normalized();
  const double span = (h - f).norm();
  while (faces[0].size() < 50) {
    const double s = -1.0 + (span + 2.0) * unit(rng);
    const Vec3 p = f + s * along;
    const bool on_base =
        std::abs(p.x()) <= 0.5 * target.base_width && std::abs(p.y()) <= 0.5 * target.base_height;
    if (on_base && (s < 0 || s > span)) faces[0].push_back(p);
  }
  return faces;
}

LrfObservation MakeObservation(const ThreeFaceTarget& target, const Noise& noise,
                               std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::array<Vec3, 3> fgh;
  const Pose cam_from_target = RandomTargetPose(target, rng, &fgh);
  const Pose lrf_from_target = TrueCamFromLrf().inverse() * cam_from_target;
  const auto faces = FacePointsInTarget(target, fgh, rng);
  LrfObservation observation;
  observation.scan.ok = observation.depth.ok = true;
  for (int k = 0; k < 3; ++k) {
    for (const Vec3& p : faces[k]) {
      const Vec3 in_lrf = lrf_from_target * p;
      EXPECT_LT(std::abs(in_lrf.z()), 1e-9);
      const Vec2 point = in_lrf.head<2>();
      observation.scan.face_points[k].push_back(point +
                                                noise.range_m * normal(rng) * point.normalized());
    }
    observation.scan.lines[k] = FitLine(observation.scan.face_points[k]);
  }
  const auto& lines = observation.scan.lines;
  observation.scan.corners = {Intersect(lines[0], lines[1]), Intersect(lines[1], lines[2]),
                              Intersect(lines[2], lines[0])};
  const auto planes = target.FacePlanes();
  for (int k = 0; k < 3; ++k) {
    Plane plane = OrientTowardsOrigin(TransformPlane(cam_from_target, planes[k]));
    const Vec3 tilt(normal(rng), normal(rng), normal(rng));
    plane.normal = ExpSO3(noise.normal_rad * tilt) * plane.normal;
    plane.distance += noise.distance_m * normal(rng);
    observation.depth.planes[k] = plane;
  }
  const auto& p = observation.depth.planes;
  observation.depth.lines = {LineOfPlanes(p[0], p[1]), LineOfPlanes(p[1], p[2]),
                             LineOfPlanes(p[2], p[0])};
  return observation;
}

std::vector<LrfObservation> MakeObservations(int count, const Noise& noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<LrfObservation> observations;
  for (int i = 0; i < count; ++i) {
    observations.push_back(MakeObservation(ThreeFaceTarget{}, noise, rng));
    observations.back().id = std::to_string(i);
  }
  return observations;
}

const Noise kPaperNoise{0.012, 0.3 * kDegree, 0.003};

LrfSolverOptions WithMethod(LrfMethod method) {
  LrfSolverOptions options;
  options.method = method;
  return options;
}

TEST(LrfSolver, MethodNamesRoundTripAndOptionsAreChecked) {
  for (LrfMethod method : {LrfMethod::kPaperLinear, LrfMethod::kRefined})
    EXPECT_EQ(ParseLrfMethod(LrfMethodName(method)), method);
  EXPECT_FALSE(ParseLrfMethod("gauss"));
  std::string why;
  EXPECT_TRUE(LrfSolverOptions{}.Check(&why));
  LrfSolverOptions bad;
  bad.huber_delta_m = 0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("huber_delta_m"), std::string::npos);
  bad = LrfSolverOptions{};
  bad.weak_eigenvalue_ratio = 1.5;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(LrfSolver, ConstraintsFollowEquationNineAndSkipObservationsWithoutFeatures) {
  auto observations = MakeObservations(3, Noise{}, 1);
  observations[1].depth.ok = false;
  const auto corners = CornerConstraints(observations);
  ASSERT_EQ(corners.size(), 12u);
  EXPECT_EQ(corners[0].observation, 0);
  EXPECT_EQ(corners[6].observation, 2);
  // F on planes 0 and 1, G on 1 and 2, H on 2 and 0.
  const int plane_of_row[6] = {0, 1, 1, 2, 2, 0};
  const int corner_of_row[6] = {0, 0, 1, 1, 2, 2};
  for (int row = 0; row < 6; ++row) {
    EXPECT_EQ(corners[6 + row].plane.normal,
              observations[2].depth.planes[plane_of_row[row]].normal);
    EXPECT_EQ(corners[6 + row].point, observations[2].scan.corners[corner_of_row[row]]);
  }
  const auto faces = FaceConstraints(observations);
  size_t expected = 0;
  for (int i : {0, 2})
    for (const auto& points : observations[i].scan.face_points) expected += points.size();
  ASSERT_EQ(faces.size(), expected);
  EXPECT_EQ(faces.back().observation, 2);
  // Noise-free: every constraint holds at the truth.
  for (const auto& c : faces)
    EXPECT_LT(
        std::abs(c.plane.SignedDistance(TrueCamFromLrf() * Vec3(c.point.x(), c.point.y(), 0))),
        1e-9);
}

TEST(LrfSolver, NoiseFreeObservationsGiveTheTruthWithBothMethods) {
  for (int count : {2, 10}) {
    const auto observations = MakeObservations(count, Noise{}, 10 + count);
    for (LrfMethod method : {LrfMethod::kPaperLinear, LrfMethod::kRefined}) {
      const LrfSolution solution = SolveLrf(observations, WithMethod(method));
      ASSERT_TRUE(solution.ok) << solution.reason;
      EXPECT_EQ(solution.method, method);
      EXPECT_LT(RotationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-6) << count;
      EXPECT_LT(TranslationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-6) << count;
      ASSERT_EQ(solution.point_to_line_m.size(), observations.size());
      EXPECT_LT(solution.mean_point_to_line_m, 1e-6);
      ASSERT_EQ(solution.point_to_plane_rms_m.size(), observations.size());
      EXPECT_LT(solution.point_to_plane_rms_m[0], 1e-6);
      EXPECT_TRUE(solution.observability.well_constrained) << count;
    }
  }
}

TEST(LrfSolver, RefinementConvergesFromAPerturbedStartOneStepAtATime) {
  const auto observations = MakeObservations(4, Noise{}, 3);
  const Pose start =
      TrueCamFromLrf() * ExpSE3((Vec6() << 0.05, -0.03, 0.04, 0.05, -0.04, 0.06).finished());
  PointPlaneSolver solver(FaceConstraints(observations), LrfSolverOptions{}, start);
  int steps = 0;
  while (solver.Step()) ++steps;
  EXPECT_TRUE(solver.Done());
  EXPECT_GE(steps, 2);
  const LrfSolution solution = solver.Summarize();
  EXPECT_TRUE(solution.converged);
  EXPECT_LT(RotationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-9);
  EXPECT_LT(TranslationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-9);
  ASSERT_EQ(solution.history.size(), solution.cost_history.size());
  EXPECT_EQ(solution.iterations + 1, static_cast<int>(solution.history.size()));
  EXPECT_TRUE(
      test::MatrixNear(solution.history.front().cam_from_lidar.matrix(), start.matrix(), 0));
  for (size_t i = 1; i < solution.cost_history.size(); ++i)
    EXPECT_LE(solution.cost_history[i], solution.cost_history[i - 1] + 1e-15);
}

// The analytic Jacobian (right perturbation) against central differences, seen through the
// solver's covariance: with all Huber weights 1, covariance = σ̂² (JᵀJ)⁻¹, so
// (Σr² / (m − 6)) · covariance⁻¹ must equal JᵀJ built from numeric derivatives.
TEST(LrfSolver, JacobianMatchesNumericDifferences) {
  const auto observations = MakeObservations(3, Noise{0.004, 0.1 * kDegree, 0.001}, 4);
  const auto constraints = FaceConstraints(observations);
  PointPlaneSolver solver(constraints, LrfSolverOptions{}, TrueCamFromLrf());
  const LrfSolution solution = solver.Run();
  for (double w : solution.robust_weights) ASSERT_EQ(w, 1.0);
  const Pose& estimate = solution.cam_from_lrf;
  auto residual = [&](const PointOnPlane& c, const Pose& pose) {
    return c.plane.SignedDistance(pose * Vec3(c.point.x(), c.point.y(), 0.0));
  };
  Mat6 numeric_information = Mat6::Zero();
  double squared = 0.0;
  const double h = 1e-6;
  for (const auto& c : constraints) {
    Eigen::Matrix<double, 1, 6> jacobian;
    for (int k = 0; k < 6; ++k) {
      const Vec6 step = h * Vec6::Unit(k);
      jacobian[k] =
          (residual(c, estimate * ExpSE3(step)) - residual(c, estimate * ExpSE3(-step))) / (2 * h);
    }
    numeric_information += jacobian.transpose() * jacobian;
    squared += residual(c, estimate) * residual(c, estimate);
  }
  const double variance_factor = squared / (static_cast<double>(constraints.size()) - 6);
  const Mat6 analytic_information = variance_factor * solution.covariance.inverse();
  EXPECT_TRUE(test::MatrixNear(analytic_information, numeric_information,
                               1e-6 * numeric_information.norm()));
  Eigen::SelfAdjointEigenSolver<Mat6> eigen(numeric_information);
  EXPECT_TRUE(test::MatrixNear(solution.observability.eigenvalues, eigen.eigenvalues(),
                               1e-6 * eigen.eigenvalues()[5]));
}

struct MeanErrors {
  double rotation_rad = 0.0;
  double translation_m = 0.0;
};

MeanErrors MeanErrorOverSeeds(LrfMethod method, int count, int seeds) {
  MeanErrors mean;
  for (int seed = 0; seed < seeds; ++seed) {
    const auto observations = MakeObservations(count, kPaperNoise, 1000 + seed);
    const LrfSolution solution = SolveLrf(observations, WithMethod(method));
    EXPECT_TRUE(solution.ok) << solution.reason;
    mean.rotation_rad += RotationError(solution.cam_from_lrf, TrueCamFromLrf()) / seeds;
    mean.translation_m += TranslationError(solution.cam_from_lrf, TrueCamFromLrf()) / seeds;
  }
  return mean;
}

TEST(LrfSolver, RefinedBeatsPaperLinearUnderNoise) {
  for (int count : {2, 10}) {
    const MeanErrors linear = MeanErrorOverSeeds(LrfMethod::kPaperLinear, count, 20);
    const MeanErrors refined = MeanErrorOverSeeds(LrfMethod::kRefined, count, 20);
    std::printf(
        "%2d observations, mean over 20 seeds: paper-linear %.3f deg %.1f mm, refined %.3f deg "
        "%.1f mm\n",
        count, linear.rotation_rad / kDegree, 1e3 * linear.translation_m,
        refined.rotation_rad / kDegree, 1e3 * refined.translation_m);
    EXPECT_LT(refined.rotation_rad, linear.rotation_rad) << count;
    EXPECT_LT(refined.translation_m, linear.translation_m) << count;
  }
}

TEST(LrfSolver, PaperLinearReportsACovarianceFromTheCornerRows) {
  const auto observations = MakeObservations(6, kPaperNoise, 5);
  const LrfSolution solution = SolveLrf(observations, WithMethod(LrfMethod::kPaperLinear));
  ASSERT_TRUE(solution.ok);
  EXPECT_GT(solution.covariance.diagonal().minCoeff(), 0.0);
  EXPECT_LT(solution.covariance.diagonal().maxCoeff(), 1.0);
  EXPECT_TRUE(solution.history.empty());
  for (double e : solution.point_to_line_m) EXPECT_GT(e, 0.0);
}

TEST(LrfSolver, PointToLineErrorOfATranslatedEstimateIsTheDistanceToEachLine) {
  const auto observations = MakeObservations(1, Noise{}, 6);
  EXPECT_LT(PointToLineError(observations[0], TrueCamFromLrf()), 1e-9);
  const Vec3 shift(0.01, -0.02, 0.005);
  Pose moved = TrueCamFromLrf();
  moved.translation() += shift;
  double expected = 0.0;
  for (const Line3& line : observations[0].depth.lines)
    expected += shift.cross(line.direction).norm() / 3.0;
  EXPECT_NEAR(PointToLineError(observations[0], moved), expected, 1e-12);
}

TEST(LrfSolver, FewerThanTwoUsableObservationsFailWithTheReason) {
  auto observations = MakeObservations(3, Noise{}, 7);
  observations[0].scan.ok = false;
  observations[2].depth.ok = false;
  for (LrfMethod method : {LrfMethod::kPaperLinear, LrfMethod::kRefined}) {
    const LrfSolution solution = SolveLrf(observations, WithMethod(method));
    EXPECT_FALSE(solution.ok);
    EXPECT_EQ(solution.reason, "fewer than two usable observations (1 of 3 had features)");
  }
  std::string why;
  EXPECT_FALSE(SolveLinearPointOnPlane(CornerConstraints(observations), &why));
  EXPECT_NE(why.find("9 unknowns"), std::string::npos) << why;
  // The same pose twice: twelve rows, but rank 6.
  const std::vector<LrfObservation> twice = {observations[1], observations[1]};
  EXPECT_FALSE(SolveLinearPointOnPlane(CornerConstraints(twice), &why));
  EXPECT_NE(why.find("rank-deficient"), std::string::npos) << why;
}

TEST(LrfSolver, AdaptiveStopsAtTheThirdObservationOnNoiseFreeData) {
  const auto sequence = MakeObservations(6, Noise{}, 8);
  const AdaptiveLrfResult result = SolveLrfAdaptive(sequence, 1e-4, LrfSolverOptions{});
  EXPECT_TRUE(result.reached_threshold);
  EXPECT_EQ(result.observations_used, 3);
  ASSERT_EQ(result.newest_error_m.size(), 1u);
  EXPECT_LT(result.newest_error_m[0], 1e-6);
  ASSERT_TRUE(result.solution.ok);
  EXPECT_EQ(result.solution.point_to_line_m.size(), 2u);  // solved from observations 0 and 1
  EXPECT_LT(TranslationError(result.solution.cam_from_lrf, TrueCamFromLrf()), 1e-6);
}

TEST(LrfSolver, AdaptiveAddsObservationsUntilTheNewestErrorIsBelowTheThreshold) {
  const auto sequence = MakeObservations(15, kPaperNoise, 9);
  for (LrfMethod method : {LrfMethod::kPaperLinear, LrfMethod::kRefined}) {
    // A threshold the first estimates miss: the median of the errors of an unreachable run.
    const AdaptiveLrfResult all = SolveLrfAdaptive(sequence, 0.0, WithMethod(method));
    EXPECT_FALSE(all.reached_threshold);
    EXPECT_EQ(all.observations_used, 15);
    ASSERT_EQ(all.newest_error_m.size(), 13u);
    ASSERT_TRUE(all.solution.ok);
    EXPECT_EQ(all.solution.point_to_line_m.size(), 15u);
    const LrfSolution direct = SolveLrf(sequence, WithMethod(method));
    EXPECT_TRUE(
        test::MatrixNear(all.solution.cam_from_lrf.matrix(), direct.cam_from_lrf.matrix(), 1e-12));

    const double threshold = 0.5 * (all.newest_error_m[0] + all.newest_error_m[1]);
    const AdaptiveLrfResult result = SolveLrfAdaptive(sequence, threshold, WithMethod(method));
    ASSERT_TRUE(result.reached_threshold) << threshold;
    EXPECT_GE(result.observations_used, 3);
    const int used = result.observations_used;
    ASSERT_EQ(static_cast<int>(result.newest_error_m.size()), used - 2);
    EXPECT_LT(result.newest_error_m.back(), threshold);
    for (int k = 0; k + 1 < used - 2; ++k) EXPECT_GE(result.newest_error_m[k], threshold);
    // Errors are those of the unreachable run up to the stop (same estimates, same order).
    for (int k = 0; k < used - 2; ++k)
      EXPECT_DOUBLE_EQ(result.newest_error_m[k], all.newest_error_m[k]);
    const std::vector<LrfObservation> prefix(sequence.begin(), sequence.begin() + used - 1);
    EXPECT_TRUE(test::MatrixNear(result.solution.cam_from_lrf.matrix(),
                                 SolveLrf(prefix, WithMethod(method)).cam_from_lrf.matrix(),
                                 1e-12));
  }
}

// Zhang & Pless boards: the scan line of each board plane (in the LRF plane), 40 points with
// range_noise_m σ along the ray.
std::vector<LrfBoardObservation> MakeBoards(int count, bool vertical, double range_noise_m,
                                            std::uint64_t seed,
                                            const Pose& cam_from_lrf = TrueCamFromLrf()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Pose lrf_from_cam = cam_from_lrf.inverse();
  std::vector<LrfBoardObservation> boards;
  for (int i = 0; i < count; ++i) {
    const double pitch = vertical ? 0.0 : 35 * kDegree * uniform(rng);
    const Vec3 board_normal = ExpSO3(Vec3(pitch, 40 * kDegree * uniform(rng), 0)) * Vec3(0, 0, -1);
    LrfBoardObservation board;
    board.camera_plane = Plane{board_normal, 1.5 + uniform(rng)};
    const Plane in_lrf = TransformPlane(lrf_from_cam, board.camera_plane);
    const Vec2 m = in_lrf.normal.head<2>();
    const Vec2 foot = -in_lrf.distance * m / m.squaredNorm();
    const Vec2 along(-m.y(), m.x());
    for (int k = 0; k < 40; ++k) {
      const Vec2 point = foot + 0.3 * uniform(rng) * along.normalized();
      board.board_points.push_back(point + range_noise_m * normal(rng) * point.normalized());
    }
    boards.push_back(board);
  }
  return boards;
}

TEST(LrfSolver, BoardsInGeneralPositionGiveTheTruth) {
  const auto boards = MakeBoards(8, false, 0.0, 11);
  for (LrfMethod method : {LrfMethod::kPaperLinear, LrfMethod::kRefined}) {
    const LrfSolution solution = SolveLrfBoard(boards, WithMethod(method));
    ASSERT_TRUE(solution.ok) << solution.reason;
    EXPECT_LT(RotationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-6);
    EXPECT_LT(TranslationError(solution.cam_from_lrf, TrueCamFromLrf()), 1e-6);
    EXPECT_TRUE(solution.observability.well_constrained);
    EXPECT_EQ(solution.point_to_plane_rms_m.size(), boards.size());
  }
}

// Vertical boards constrain nothing along camera y: the height of the LRF is unobservable (a null
// direction of JᵀWJ) and must be reported. With the LRF tilted by a few degrees, rotations about
// the horizontal axes remain observable, if weakly (eigenvalues ∝ sin² of the tilt).
TEST(LrfSolver, VerticalBoardsReportTheUnobservableHeight) {
  const auto boards = MakeBoards(8, true, 0.002, 12);
  const LrfSolution no_seed = SolveLrfBoard(boards, LrfSolverOptions{});
  EXPECT_FALSE(no_seed.ok);
  EXPECT_NE(no_seed.reason.find("rank-deficient"), std::string::npos) << no_seed.reason;

  const Pose seed =
      TrueCamFromLrf() * ExpSE3((Vec6() << 0.02, 0.03, -0.02, 0.01, 0.01, -0.02).finished());
  const LrfSolution solution = SolveLrfBoard(boards, LrfSolverOptions{}, seed);
  ASSERT_TRUE(solution.ok) << solution.reason;
  EXPECT_FALSE(solution.observability.well_constrained);
  ASSERT_EQ(solution.observability.weak_directions.size(), 1u);
  EXPECT_EQ(solution.observability.weak_directions[0], "translation along camera y (down)");
  // The height stays at the seed; the boards fix the rest (rotation to about a degree with 2 mm
  // of range noise, being weakly observed).
  EXPECT_NEAR(solution.cam_from_lrf.translation().y(), seed.translation().y(), 1e-3);
  EXPECT_NEAR(solution.cam_from_lrf.translation().x(), TrueCamFromLrf().translation().x(), 5e-3);
  EXPECT_NEAR(solution.cam_from_lrf.translation().z(), TrueCamFromLrf().translation().z(), 5e-3);
  EXPECT_LT(RotationError(solution.cam_from_lrf, TrueCamFromLrf()), 2 * kDegree);
  // Its variance is not hidden.
  const Vec3 down_in_lrf = solution.cam_from_lrf.linear().transpose() * Vec3::UnitY();
  EXPECT_GT(down_in_lrf.dot(solution.covariance.topLeftCorner<3, 3>() * down_in_lrf), 1.0);
}

// A level LRF with vertical boards: the height and both rotations about horizontal axes are null
// directions, all three reported.
TEST(LrfSolver, VerticalBoardsAndALevelScanReportThreeWeakDirections) {
  Pose level = TrueCamFromLrf();
  level.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const auto boards = MakeBoards(8, true, 0.0, 13, level);
  const Pose seed = level * ExpSE3((Vec6() << 0.02, 0.03, -0.02, 0.01, 0.01, -0.02).finished());
  const LrfSolution solution = SolveLrfBoard(boards, LrfSolverOptions{}, seed);
  ASSERT_TRUE(solution.ok) << solution.reason;
  EXPECT_FALSE(solution.observability.well_constrained);
  const std::vector<std::string> expected = {"translation along camera y (down)",
                                             "rotation about camera x (right) through the LRF "
                                             "origin",
                                             "rotation about camera z (forward) through the LRF "
                                             "origin"};
  EXPECT_EQ(solution.observability.weak_directions, expected);
  // The observable part (x, z translation and rotation about y) is recovered.
  EXPECT_NEAR(solution.cam_from_lrf.translation().x(), level.translation().x(), 1e-3);
  EXPECT_NEAR(solution.cam_from_lrf.translation().z(), level.translation().z(), 1e-3);
}

}  // namespace
}  // namespace calibench
