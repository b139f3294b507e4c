// The rig solve (core/lidar_camera/rig_solver.h) on simulated measurements: one LiDAR and two
// cameras, the second looking 60° aside with fields of view that overlap partly. Each camera's
// pose is as good as its single-camera solve, and the cameras' relative pose is better than the
// one composed from two single-camera solves, with a σ that can be trusted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/lidar_camera/rig_solver.h"

namespace calibench {
namespace {

constexpr double kDeg = M_PI / 180.0;

Mat3 RotationZ(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(); }

// Camera 0 looks along the LiDAR's x axis; camera 1 is turned 60° to the left (about the LiDAR's
// z axis) and sits 25 cm to the left.
struct RigTruth {
  Pose cam_from_lidar[2];
};
RigTruth MakeRig() {
  Pose lidar_from_cam0 = Pose::Identity();
  // Camera axes (x right, y down, z forward) in the LiDAR frame (x forward, y left, z up).
  lidar_from_cam0.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  lidar_from_cam0.translation() = Vec3(0.05, -0.10, -0.08);
  Pose lidar_from_cam1 = Pose::Identity();
  lidar_from_cam1.linear() = RotationZ(60 * kDeg) * lidar_from_cam0.linear();
  lidar_from_cam1.translation() = Vec3(0.02, 0.25, -0.06);
  return {{lidar_from_cam0.inverse(), lidar_from_cam1.inverse()}};
}

// The board's pose noise as PnP reports it (right perturbation in the board frame): tilt and depth
// worse than the in-plane directions, growing with the range.
Mat6 PnpCovariance(double range_m) {
  Vec6 sigma;
  const double scale = range_m / 2.0;
  sigma << 0.001 * scale, 0.001 * scale, 0.004 * scale, 0.15 * kDeg, 0.15 * kDeg, 0.05 * kDeg;
  return sigma.cwiseAbs2().asDiagonal();
}

// Draws x ~ N(0, covariance) (covariance positive definite).
template <int N>
Eigen::Matrix<double, N, 1> Draw(const Eigen::Matrix<double, N, N>& covariance, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, N, 1> z;
  for (int i = 0; i < N; ++i) z[i] = normal(rng);
  return Eigen::LLT<Eigen::Matrix<double, N, N>>(covariance).matrixL() * z;
}

// One trial's captures: boards spread from 40° right of camera 0 to 40° left of camera 1, each
// seen by the cameras whose field (±50° about the optical axis) holds it.
std::vector<RigCapture> SimulateCaptures(const RigTruth& truth, int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> azimuth(-40 * kDeg, 100 * kDeg), range(1.5, 4.0),
      height(-0.3, 0.5), tilt(-30 * kDeg, 30 * kDeg), spin(-M_PI, M_PI);
  std::vector<RigCapture> captures;
  while (static_cast<int>(captures.size()) < count) {
    const double a = azimuth(rng), r = range(rng);
    const Vec3 center(r * std::cos(a), r * std::sin(a), height(rng));
    // The board faces the LiDAR (its z axis away from it), tilted and turned in its plane.
    const Vec3 z = center.normalized();
    const Vec3 x = Vec3::UnitZ().cross(z).normalized();
    Mat3 facing;
    facing << x, z.cross(x), z;
    Pose lidar_from_board = Pose::Identity();
    lidar_from_board.linear() = facing * Eigen::AngleAxisd(tilt(rng), Vec3::UnitX()) *
                                Eigen::AngleAxisd(tilt(rng), Vec3::UnitY()) *
                                Eigen::AngleAxisd(spin(rng), Vec3::UnitZ());
    lidar_from_board.translation() = center;
    RigCapture capture;
    capture.id = "c" + std::to_string(captures.size());
    for (int c = 0; c < 2; ++c) {
      const Pose cam_from_board = truth.cam_from_lidar[c] * lidar_from_board;
      const Vec3 in_cam = cam_from_board.translation();
      if (in_cam.z() < 0.5 || std::acos(in_cam.normalized().z()) > 50 * kDeg) continue;
      const Mat6 covariance = PnpCovariance(in_cam.norm());
      capture.views.push_back({c, cam_from_board * ExpSE3(Draw<6>(covariance, rng)), covariance});
    }
    if (capture.views.empty()) continue;
    const Plane true_plane = OrientTowardsOrigin(
        Plane{lidar_from_board.linear().col(2),
              -lidar_from_board.linear().col(2).dot(lidar_from_board.translation())});
    Mat3 tangent = Vec3(0.4 * kDeg, 0.4 * kDeg, 0.004).cwiseAbs2().asDiagonal();
    const Vec3 noise = Draw<3>(tangent, rng);
    Plane measured = true_plane;
    measured.normal =
        (true_plane.normal + PlaneTangentBasis(true_plane.normal) * noise.head<2>()).normalized();
    measured.distance += noise.z();
    capture.lidar_plane = measured;
    capture.lidar_covariance = TangentToPlaneCovariance(tangent, measured.normal);
    captures.push_back(std::move(capture));
  }
  return captures;
}

// The captures one camera saw, as a rig of that camera alone.
std::vector<RigCapture> OneCamera(const std::vector<RigCapture>& captures, int camera) {
  std::vector<RigCapture> alone;
  for (const RigCapture& capture : captures)
    for (const RigBoardView& view : capture.views)
      if (view.camera == camera) {
        RigCapture copy = capture;
        copy.views = {view};
        copy.views.front().camera = 0;
        alone.push_back(std::move(copy));
      }
  return alone;
}

Pose Perturbed(const Pose& pose, std::mt19937& rng) {
  Vec6 xi;
  std::normal_distribution<double> normal;
  for (int i = 0; i < 3; ++i) xi[i] = 0.02 * normal(rng);
  for (int i = 3; i < 6; ++i) xi[i] = 1.0 * kDeg * normal(rng);
  return pose * ExpSE3(xi);
}

struct Rms {
  double t2 = 0.0, r2 = 0.0;
  int n = 0;
  void Add(const Pose& estimate, const Pose& truth) {
    const PoseError e = ComputePoseError(estimate, truth);
    t2 += e.translation_m * e.translation_m;
    r2 += e.rotation_rad * e.rotation_rad;
    ++n;
  }
  double TranslationMm() const { return 1e3 * std::sqrt(t2 / n); }
  double RotationDeg() const { return std::sqrt(r2 / n) / kDeg; }
};

TEST(RigSolver, TheBoardTiesTheCamerasBetterThanComposingTwoSingleCameraSolves) {
  const RigTruth truth = MakeRig();
  const Pose true_1_from_0 = truth.cam_from_lidar[1] * truth.cam_from_lidar[0].inverse();
  std::mt19937 rng(11);
  Rms single[2], joint[2], composed, relative;
  double nees = 0.0;
  int shared = 0;
  constexpr int kTrials = 40;
  for (int trial = 0; trial < kTrials; ++trial) {
    const std::vector<RigCapture> captures = SimulateCaptures(truth, 30, rng);
    for (const RigCapture& capture : captures) shared += capture.views.size() == 2;
    std::string why;
    Pose alone[2];
    for (int c = 0; c < 2; ++c) {
      const auto solved =
          SolveRig(OneCamera(captures, c), {Perturbed(truth.cam_from_lidar[c], rng)}, {}, &why);
      ASSERT_TRUE(solved && solved->converged) << why;
      alone[c] = solved->cam_from_lidar[0];
      single[c].Add(alone[c], truth.cam_from_lidar[c]);
    }
    composed.Add(alone[1] * alone[0].inverse(), true_1_from_0);
    const auto both = SolveRig(captures, {alone[0], alone[1]}, {}, &why);
    ASSERT_TRUE(both && both->converged) << why;
    for (int c = 0; c < 2; ++c) joint[c].Add(both->cam_from_lidar[c], truth.cam_from_lidar[c]);
    const RelativePose one_from_zero = CameraFromCamera(*both, 1, 0);
    relative.Add(one_from_zero.to_from_from, true_1_from_0);
    const Vec6 error = LogSE3(one_from_zero.to_from_from.inverse() * true_1_from_0);
    nees += error.dot(one_from_zero.covariance.ldlt().solve(error));
  }
  nees /= kTrials;
  std::printf("%d trials, 30 captures each, %.1f seen by both cameras on average\n", kTrials,
              static_cast<double>(shared) / kTrials);
  for (int c = 0; c < 2; ++c)
    std::printf("camera %d: single %.2f mm %.3f deg, joint %.2f mm %.3f deg (RMS)\n", c,
                single[c].TranslationMm(), single[c].RotationDeg(), joint[c].TranslationMm(),
                joint[c].RotationDeg());
  std::printf("cam1_from_cam0: composed %.2f mm %.3f deg, joint %.2f mm %.3f deg; NEES %.2f (6)\n",
              composed.TranslationMm(), composed.RotationDeg(), relative.TranslationMm(),
              relative.RotationDeg(), nees);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LE(joint[c].TranslationMm(), 1.05 * single[c].TranslationMm()) << c;
    EXPECT_LE(joint[c].RotationDeg(), 1.05 * single[c].RotationDeg()) << c;
  }
  EXPECT_LT(relative.TranslationMm(), 0.8 * composed.TranslationMm());
  EXPECT_LT(relative.RotationDeg(), composed.RotationDeg());
  // χ²(6) has mean 6: the joint σ of the relative pose is the spread it shows.
  EXPECT_GT(nees, 4.0);
  EXPECT_LT(nees, 8.5);
}

// What CalibrateRig runs: the cameras' own calibrations as priors (here the single-camera plane
// solves with their covariances), the shared boards tying them. Each camera no worse than alone,
// the relative pose better than composed, and no σ narrower than the spread (the priors share
// the LiDAR planes of the shared captures, which the widening accounts for).
TEST(RigSolver, TheCamerasOwnCalibrationsTiedByTheSharedBoards) {
  const RigTruth truth = MakeRig();
  const Pose true_1_from_0 = truth.cam_from_lidar[1] * truth.cam_from_lidar[0].inverse();
  std::mt19937 rng(17);
  Rms single[2], joint[2], composed, relative;
  double nees_relative = 0.0, nees_camera[2] = {0.0, 0.0};
  constexpr int kTrials = 40;
  for (int trial = 0; trial < kTrials; ++trial) {
    const std::vector<RigCapture> captures = SimulateCaptures(truth, 30, rng);
    std::string why;
    std::vector<RigCameraPrior> alone;
    for (int c = 0; c < 2; ++c) {
      const auto solved =
          SolveRig(OneCamera(captures, c), {Perturbed(truth.cam_from_lidar[c], rng)}, {}, &why);
      ASSERT_TRUE(solved && solved->converged) << why;
      alone.push_back({solved->cam_from_lidar[0], solved->covariance});
      single[c].Add(alone[c].cam_from_lidar, truth.cam_from_lidar[c]);
    }
    composed.Add(alone[1].cam_from_lidar * alone[0].cam_from_lidar.inverse(), true_1_from_0);
    int shared = 0;
    const auto both = SolveRigFromCameras(captures, alone, {}, &why, &shared);
    ASSERT_TRUE(both && both->converged) << why;
    EXPECT_GT(shared, 0);
    for (int c = 0; c < 2; ++c) {
      joint[c].Add(both->cam_from_lidar[c], truth.cam_from_lidar[c]);
      const Vec6 error = LogSE3(both->cam_from_lidar[c].inverse() * truth.cam_from_lidar[c]);
      nees_camera[c] += error.dot(both->covariance.block<6, 6>(6 * c, 6 * c).ldlt().solve(error));
    }
    const RelativePose one_from_zero = CameraFromCamera(*both, 1, 0);
    relative.Add(one_from_zero.to_from_from, true_1_from_0);
    const Vec6 error = LogSE3(one_from_zero.to_from_from.inverse() * true_1_from_0);
    nees_relative += error.dot(one_from_zero.covariance.ldlt().solve(error));
  }
  for (int c = 0; c < 2; ++c) {
    nees_camera[c] /= kTrials;
    std::printf("camera %d: alone %.2f mm %.3f deg, joint %.2f mm %.3f deg (RMS); NEES %.2f\n", c,
                single[c].TranslationMm(), single[c].RotationDeg(), joint[c].TranslationMm(),
                joint[c].RotationDeg(), nees_camera[c]);
    EXPECT_LE(joint[c].TranslationMm(), 1.05 * single[c].TranslationMm()) << c;
    EXPECT_LE(joint[c].RotationDeg(), 1.05 * single[c].RotationDeg()) << c;
    EXPECT_LT(nees_camera[c], 8.5) << c;  // not narrower than its spread
  }
  nees_relative /= kTrials;
  std::printf("cam1_from_cam0: composed %.2f mm %.3f deg, joint %.2f mm %.3f deg; NEES %.2f (6)\n",
              composed.TranslationMm(), composed.RotationDeg(), relative.TranslationMm(),
              relative.RotationDeg(), nees_relative);
  EXPECT_LT(relative.TranslationMm(), 0.8 * composed.TranslationMm());
  EXPECT_LT(relative.RotationDeg(), composed.RotationDeg());
  EXPECT_LT(nees_relative, 8.5);
  EXPECT_GT(nees_relative, 2.0);  // nor much wider
}

TEST(RigSolver, ACameraTheCapturesDoNotDetermineIsNamed) {
  const RigTruth truth = MakeRig();
  std::mt19937 rng(3);
  std::vector<RigCapture> captures = OneCamera(SimulateCaptures(truth, 12, rng), 0);
  captures.resize(2);
  std::string why;
  EXPECT_FALSE(SolveRig(captures, {truth.cam_from_lidar[0]}, {}, &why));
  EXPECT_NE(why.find("camera 0 sees the board in 2 capture(s)"), std::string::npos) << why;
  captures = SimulateCaptures(truth, 12, rng);
  captures[0].views[0].pose_covariance = Mat6::Zero();
  EXPECT_FALSE(SolveRig(captures, {truth.cam_from_lidar[0], truth.cam_from_lidar[1]}, {}, &why));
  EXPECT_NE(why.find("not positive definite"), std::string::npos) << why;
}

}  // namespace
}  // namespace calibench
