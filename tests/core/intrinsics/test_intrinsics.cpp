// CalibrateIntrinsics on corners projected through known cameras: the truth recovered, the σ
// honest, a bad view rejected with its reason, and the coverage verdict naming what is missing.
#include <gtest/gtest.h>

#include <random>

#include "core/intrinsics/intrinsics.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

// Views of a 9x6-corner board (40 mm squares) at random poses 0.6-1.5 m away, its centre
// anywhere in the image whose size is `spread` of the image (1 = the whole image), tilted up to
// 40 deg; pixel noise `noise_px`. The corners outside the image are left out (a partial view, as
// ChArUco gives), at least 20 kept.
std::vector<IntrinsicsView> ProjectedViews(const CameraModel& camera, int count, double spread,
                                           double noise_px, std::uint64_t seed) {
  BoardSpec board;
  board.cols = 9, board.rows = 6, board.square_size = 0.04;
  const std::vector<Vec3> points = BoardCornerPoints(board);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<IntrinsicsView> views;
  while (static_cast<int>(views.size()) < count) {
    const double depth = 0.6 + 0.45 * (unit(rng) + 1.0);
    const Vec2 pixel(camera.width * (0.5 + 0.5 * spread * unit(rng)),
                     camera.height * (0.5 + 0.5 * spread * unit(rng)));
    const auto bearing = camera.Unproject(pixel);
    if (!bearing) continue;
    Pose cam_from_board = Pose::Identity();
    cam_from_board.linear() = (Eigen::AngleAxisd(0.7 * unit(rng), Vec3::UnitX()) *
                               Eigen::AngleAxisd(0.7 * unit(rng), Vec3::UnitY()) *
                               Eigen::AngleAxisd(0.3 * unit(rng), Vec3::UnitZ()))
                                  .toRotationMatrix();
    cam_from_board.translation() = *bearing / bearing->z() * depth;
    IntrinsicsView view{"view" + std::to_string(views.size()), {}};
    for (const Vec3& p : points) {
      const auto projected = camera.Project(cam_from_board * p);
      if (!projected || !camera.InImage(*projected, 1.0)) continue;
      view.detection.pixels.push_back(*projected + Vec2(noise(rng), noise(rng)));
      view.detection.board_points.push_back(p);
    }
    if (view.detection.pixels.size() >= 20) views.push_back(std::move(view));
  }
  return views;
}

void ExpectRecovered(const IntrinsicsResult& r, const CameraModel& truth, double tolerance) {
  EXPECT_NEAR(r.camera.fx, truth.fx, tolerance * truth.fx);
  EXPECT_NEAR(r.camera.fy, truth.fy, tolerance * truth.fy);
  EXPECT_NEAR(r.camera.cx, truth.cx, tolerance * truth.cx);
  EXPECT_NEAR(r.camera.cy, truth.cy, tolerance * truth.cy);
}

TEST(Intrinsics, PinholeAndFisheyeRecoveredWithHonestSigma) {
  for (const bool fisheye : {false, true}) {
    const CameraModel truth = DefaultSimCamera(fisheye);
    IntrinsicsOptions options;
    options.model = truth.type;
    const IntrinsicsResult exact = CalibrateIntrinsics(ProjectedViews(truth, 25, 0.9, 0.0, 3),
                                                       truth.width, truth.height, options);
    ExpectRecovered(exact, truth, 1e-6);
    EXPECT_LT(exact.rms_px, 0.005);  // fisheye::calibrate stops at ~0.002 px
    // With 0.3 px of noise: within 3.5 σ per parameter, over 8 seeds.
    int within = 0, total = 0;
    for (std::uint64_t seed = 10; seed < 18; ++seed) {
      const IntrinsicsResult noisy = CalibrateIntrinsics(ProjectedViews(truth, 25, 0.9, 0.3, seed),
                                                         truth.width, truth.height, options);
      EXPECT_NEAR(noisy.rms_px, 0.3 * std::sqrt(2.0), 0.05);  // per corner, both axes
      const std::vector<double> true_values = {truth.fx, truth.fy, truth.cx, truth.cy};
      for (int i = 0; i < 4; ++i) {
        ++total;
        within += std::abs(noisy.parameters[i] - true_values[i]) < 3.5 * noisy.sigmas[i];
        EXPECT_GT(noisy.sigmas[i], 0.0);
      }
    }
    EXPECT_GE(within, total - 1) << (fisheye ? "fisheye" : "pinhole");
  }
}

TEST(Intrinsics, ABadViewIsRejectedWithItsReason) {
  const CameraModel truth = DefaultSimCamera(false);
  std::vector<IntrinsicsView> views = ProjectedViews(truth, 15, 0.9, 0.2, 5);
  for (size_t k = 0; k < views[4].detection.pixels.size(); k += 2)
    views[4].detection.pixels[k] += Vec2(4.0, -3.0);  // a misdetection
  const IntrinsicsResult r =
      CalibrateIntrinsics(views, truth.width, truth.height, IntrinsicsOptions{});
  ASSERT_EQ(r.images.size(), 15u);
  EXPECT_FALSE(r.images[4].used);
  EXPECT_NE(r.images[4].reason.find("corner RMS"), std::string::npos) << r.images[4].reason;
  for (size_t i = 0; i < r.images.size(); ++i) {
    if (i != 4) {
      EXPECT_TRUE(r.images[i].used) << i;
    }
  }
  // Within 4 σ of the truth, which the bad view alone would have pushed far out.
  const std::vector<double> true_values = {truth.fx, truth.fy, truth.cx, truth.cy};
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(std::abs(r.parameters[i] - true_values[i]), 4.0 * r.sigmas[i]) << i;
  EXPECT_NE(FormatIntrinsics(r).find("not used: corner RMS"), std::string::npos);
}

TEST(Intrinsics, TheCoverageVerdictNamesTheMissingBorder) {
  const CameraModel truth = DefaultSimCamera(false);
  // Boards in the middle only: every border is missing, and the verdict says so.
  const IntrinsicsResult centre = CalibrateIntrinsics(
      ProjectedViews(truth, 20, 0.25, 0.2, 7), truth.width, truth.height, IntrinsicsOptions{});
  EXPECT_FALSE(centre.good);
  for (const char* border : {"left border", "right border", "top border", "bottom border"})
    EXPECT_NE(centre.verdict.find(border), std::string::npos) << centre.verdict;
  // Boards everywhere: good, in words.
  const IntrinsicsResult everywhere = CalibrateIntrinsics(
      ProjectedViews(truth, 60, 1.0, 0.2, 8), truth.width, truth.height, IntrinsicsOptions{});
  EXPECT_TRUE(everywhere.good) << everywhere.verdict;
  EXPECT_EQ(everywhere.verdict.rfind("good", 0), 0u) << everywhere.verdict;
  EXPECT_TRUE(everywhere.coverage.missing.empty());
  // Only the right third empty: the right border (and nothing else) named.
  std::vector<IntrinsicsView> left;
  for (IntrinsicsView& v : ProjectedViews(truth, 80, 1.0, 0.2, 9)) {
    bool right = false;
    for (const Vec2& p : v.detection.pixels) right |= p.x() > 0.8 * truth.width;
    if (!right) left.push_back(std::move(v));
  }
  ASSERT_GE(left.size(), 10u);
  const IntrinsicsCoverage coverage =
      MeasureCoverage(left, truth.width, truth.height, IntrinsicsOptions{});
  ASSERT_FALSE(coverage.missing.empty());
  EXPECT_EQ(coverage.missing.front(), "right border");
  for (const std::string& m : coverage.missing) EXPECT_EQ(m.find("left"), std::string::npos) << m;
}

}  // namespace
}  // namespace calibench
