// The three-face target's geometry and the LRF ↔ depth camera simulator against its own ground
// truth: scan points on the faces, the depth noise model, pose sampling, determinism and stereo.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using test::MatrixNear;
using test::TempDir;

// A 320x180 camera with the default's field of view, for fast file tests.
LrfSimOptions SmallOptions(const std::string& preset) {
  LrfSimOptions options = *LrfSimPreset(preset);
  options.depth.intrinsics = DepthIntrinsics{320, 180, 175.0, 175.0, 160.0, 90.0, 0.001};
  options.observations = 3;
  return options;
}

TEST(ThreeFaceTarget, FacePlanesContainTheirCornersAndFaceTheSensors) {
  const ThreeFaceTarget target;
  std::string why;
  ASSERT_TRUE(target.Check(&why)) << why;
  const auto planes = target.FacePlanes();
  const Vec3 on_face[3][3] = {{target.A(), target.B(), target.D()},
                              {target.A(), target.B(), target.C()},
                              {target.A(), target.C(), target.D()}};
  for (int f = 0; f < 3; ++f) {
    EXPECT_NEAR(planes[f].normal.norm(), 1.0, 1e-12);
    EXPECT_GT(planes[f].normal.z(), 0.0) << f;
    for (const Vec3& p : on_face[f]) EXPECT_NEAR(planes[f].SignedDistance(p), 0.0, 1e-12) << f;
  }
  EXPECT_LT(planes[1].normal.x(), 0.0);  // ABC leans to the left (-x), ACD to the right
  EXPECT_GT(planes[2].normal.x(), 0.0);
}

TEST(ThreeFaceTarget, CheckRejectsImpossibleShapes) {
  std::string why;
  ThreeFaceTarget t;
  t.tent_half_width = 0.4;  // as wide as the base: no base margin left
  EXPECT_FALSE(t.Check(&why));
  t = ThreeFaceTarget();
  t.apex_y = t.foot_y;
  EXPECT_FALSE(t.Check(&why));
  t = ThreeFaceTarget();
  t.ridge_height = 0.0;
  EXPECT_FALSE(t.Check(&why));
  t = ThreeFaceTarget();
  t.ridge_height = 0.005;  // faces nearly parallel to the base
  EXPECT_FALSE(t.Check(&why));
  EXPECT_NE(why.find("parallel"), std::string::npos) << why;
  t = ThreeFaceTarget();
  t.apex_y = 0.35;  // outside the 0.6 m base
  EXPECT_FALSE(t.Check(&why));
  DepthIntrinsics in;
  EXPECT_FALSE(in.Check(&why));
}

TEST(LrfSim, PresetsAndOptionChecks) {
  std::string why;
  ASSERT_TRUE(LrfSimPreset("paper").has_value());
  EXPECT_TRUE(LrfSimPreset("paper")->Check(&why)) << why;
  EXPECT_EQ(LrfSimPreset("paper")->lrf.angular_step_deg, 0.042);
  EXPECT_EQ(LrfSimPreset("ideal")->lrf.range_noise_m, 0.0);
  EXPECT_EQ(LrfSimPreset("ideal")->depth.disparity_noise_px, 0.0);
  EXPECT_FALSE(LrfSimPreset("kinect").has_value());
  LrfSimOptions bad;
  bad.target_distance_min_m = 4.0;
  EXPECT_FALSE(bad.Check(&why));
  bad = LrfSimOptions();
  bad.lrf.angular_step_deg = 0.0;
  EXPECT_FALSE(bad.Check(&why));
  bad = LrfSimOptions();
  bad.depth.stereo_baseline_m = 0.0;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(LrfSim, DefaultMountIsLevelForwardAboveAndBehind) {
  const Pose cam_from_lrf = DefaultCamFromLrf();
  const double deg = M_PI / 180.0;
  EXPECT_LT(std::acos((cam_from_lrf.linear() * Vec3::UnitX()).dot(Vec3::UnitZ())), 5 * deg);
  EXPECT_LT(std::acos((cam_from_lrf.linear() * Vec3::UnitY()).dot(-Vec3::UnitX())), 5 * deg);
  EXPECT_LT(std::acos((cam_from_lrf.linear() * Vec3::UnitZ()).dot(-Vec3::UnitY())), 5 * deg);
  EXPECT_GT(
      RotationAngle(cam_from_lrf.linear(), (Mat3() << 0, -1, 0, 0, 0, -1, 1, 0, 0).finished()),
      0.5 * deg);  // not exactly the axis swap
  EXPECT_TRUE(MatrixNear(cam_from_lrf.translation(), Vec3(0, -0.15, -0.10), 1e-12));
}

// For every sampled pose, the noise-free scan hits E…F, ABC, ACD and H…I, and each point on the
// target lies on its face plane (target frame) to 1e-9 m.
TEST(LrfSim, NoiseFreeScanLiesOnTheFacesForEverySampledPose) {
  LrfSimOptions options = *LrfSimPreset("ideal");
  options.observations = 8;
  const std::vector<Pose> poses = SampleTargetPoses(options);
  ASSERT_EQ(poses.size(), 8u);
  const ThreeFaceTarget& target = options.target;
  const auto planes = target.FacePlanes();
  for (const Pose& cam_from_target : poses) {
    const LaserScan scan = RenderLrfObservation(options, cam_from_target, 7).scan;
    const Pose target_from_lrf = cam_from_target.inverse() * options.cam_from_lrf;
    int counts[4] = {0, 0, 0, 0};  // base left, ABC, ACD, base right
    for (size_t i = 0; i < scan.ranges.size(); ++i) {
      if (!scan.Valid(i)) continue;
      const Vec3 p = target_from_lrf * Vec3(scan.Point(i).x(), scan.Point(i).y(), 0.0);
      if (std::abs(p.x()) > 0.5 * target.base_width + 0.01 ||
          std::abs(p.y()) > 0.5 * target.base_height + 0.01 || p.z() < -0.01 ||
          p.z() > target.ridge_height + 0.01)
        continue;  // clutter
      int face = -1;
      double best = 1e9;
      for (int f = 0; f < 3; ++f) {
        const double distance = std::abs(planes[f].SignedDistance(p));
        if (distance < best) best = distance, face = f;
      }
      EXPECT_LT(best, 1e-9) << "point " << p.transpose();
      if (face == 0) ++counts[p.x() < 0 ? 0 : 3];
      if (face > 0) ++counts[face];
    }
    for (int segment = 0; segment < 4; ++segment)
      EXPECT_GE(counts[segment], 20) << "segment " << segment;
  }
}

TEST(LrfSim, DepthNoiseMatchesTheStereoModel) {
  LrfSimOptions noisy = *LrfSimPreset("paper");
  noisy.clutter = false;
  LrfSimOptions exact = noisy;
  exact.depth.disparity_noise_px = 0.0;
  Pose cam_from_target = Pose::Identity();  // facing the camera, base at z = 2 m
  cam_from_target.linear() = Vec3(1, -1, -1).asDiagonal();
  cam_from_target.translation() = Vec3(0, 0, 2.0);
  const DepthImage a = RenderLrfObservation(noisy, cam_from_target, 11).depth;
  const DepthImage b = RenderLrfObservation(exact, cam_from_target, 11).depth;
  double sum = 0, sum2 = 0;
  int n = 0;
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    if (std::abs(b.depth_m[i] - 2.0) > 1e-5 || a.depth_m[i] == 0) continue;  // base pixels
    const double e = a.depth_m[i] - b.depth_m[i];
    sum += e, sum2 += e * e, ++n;
  }
  ASSERT_GT(n, 10000);
  const double mean = sum / n, std_dev = std::sqrt(sum2 / n - mean * mean);
  const double model = 2.0 * 2.0 * noisy.depth.disparity_noise_px /
                       (noisy.depth.intrinsics.fx * noisy.depth.stereo_baseline_m);
  EXPECT_NEAR(std_dev / model, 1.0, 0.15) << "std " << std_dev << " model " << model;
  EXPECT_LT(std::abs(mean), 0.1 * model);
}

TEST(LrfSim, RangeNoiseMatchesTheSpec) {
  LrfSimOptions noisy = *LrfSimPreset("paper");
  LrfSimOptions exact = *LrfSimPreset("ideal");
  const Pose pose = SampleTargetPoses(noisy).front();
  const LaserScan a = RenderLrfObservation(noisy, pose, 3).scan;
  const LaserScan b = RenderLrfObservation(exact, pose, 3).scan;
  double sum2 = 0;
  int n = 0;
  for (size_t i = 0; i < a.ranges.size(); ++i)
    if (a.Valid(i) && b.Valid(i)) sum2 += std::pow(a.ranges[i] - b.ranges[i], 2), ++n;
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(std::sqrt(sum2 / n) / noisy.lrf.range_noise_m, 1.0, 0.1);
}

TEST(LrfSim, SamplingIsDeterministicPerSeed) {
  LrfSimOptions options = SmallOptions("paper");
  const auto first = SampleTargetPoses(options);
  const auto second = SampleTargetPoses(options);
  ASSERT_EQ(first.size(), 3u);
  ASSERT_EQ(second.size(), 3u);
  for (size_t i = 0; i < first.size(); ++i)
    EXPECT_TRUE(MatrixNear(first[i].matrix(), second[i].matrix(), 0.0));
  options.seed = 2;
  EXPECT_FALSE(MatrixNear(SampleTargetPoses(options)[0].matrix(), first[0].matrix(), 1e-6));
  for (const Pose& pose : first) {
    EXPECT_GE(pose.translation().norm(), options.target_distance_min_m - 0.3);
    EXPECT_LE(pose.translation().norm(), options.target_distance_max_m + 0.3);
    EXPECT_LT((pose.linear() * Vec3::UnitZ()).z(), 0.0);  // target +z towards the camera
    EXPECT_LT((pose.linear() * Vec3::UnitY()).y(), 0.0);  // upright: target y ≈ camera -y
  }
}

TEST(LrfSim, WrittenDatasetIsDeterministicAndLoads) {
  LrfSimOptions options = SmallOptions("paper");
  options.stereo = true;
  const fs::path dir_a = TempDir("lrf_sim_a"), dir_b = TempDir("lrf_sim_b");
  const fs::path manifest = WriteLrfSimDataset(options, dir_a);
  WriteLrfSimDataset(options, dir_b);
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir_a)) {
    if (!entry.is_regular_file()) continue;
    ++files;
    const fs::path other = dir_b / entry.path().lexically_relative(dir_a);
    EXPECT_EQ(test::ReadFileBytes(entry.path()), test::ReadFileBytes(other)) << entry.path();
  }
  EXPECT_EQ(files, 2 + 3 * 3);  // two manifests, scans, depth, depth_right
  const LrfDataset dataset = LoadLrfDataset(manifest);
  ASSERT_EQ(dataset.pairs.size(), 3u);
  ASSERT_TRUE(dataset.cam_from_lrf_ground_truth.has_value());
  EXPECT_TRUE(MatrixNear(dataset.cam_from_lrf_ground_truth->matrix(), options.cam_from_lrf.matrix(),
                         1e-12));
  const DepthImage depth = LoadPairDepth(dataset, dataset.pairs[0]);
  EXPECT_EQ(depth.intrinsics.width, 320);
  const LaserScan scan = LoadLaserScan(dataset.pairs[0].scan);
  EXPECT_NEAR(scan.angle_increment, 0.042 * M_PI / 180.0, 1e-15);
  options.seed = 9;
  const fs::path dir_c = TempDir("lrf_sim_c");
  WriteLrfSimDataset(options, dir_c);
  EXPECT_NE(test::ReadFileBytes(dir_a / "scans/0000.json"),
            test::ReadFileBytes(dir_c / "scans/0000.json"));
}

TEST(LrfSim, StereoGroundTruthAndRightDepthAgreeWithTheLeft) {
  LrfSimOptions options = SmallOptions("ideal");
  options.stereo = true;
  options.observations = 1;
  const fs::path dir = TempDir("lrf_sim_stereo");
  WriteLrfSimDataset(options, dir);
  const LrfDataset left = LoadLrfDataset(dir / "manifest.json");
  const LrfDataset right = LoadLrfDataset(dir / "right.json");
  ASSERT_TRUE(left.right_from_left && right.right_from_left);
  EXPECT_TRUE(MatrixNear(left.right_from_left->translation(), Vec3(-0.12, 0, 0), 1e-12));
  EXPECT_TRUE(MatrixNear(left.right_from_left->linear(), Mat3::Identity(), 1e-12));
  EXPECT_TRUE(MatrixNear(right.right_from_left->matrix(), left.right_from_left->matrix(), 0.0));
  EXPECT_TRUE(MatrixNear(right.cam_from_lrf_ground_truth->matrix(),
                         (*left.right_from_left * *left.cam_from_lrf_ground_truth).matrix(),
                         1e-12));
  EXPECT_EQ(right.pairs[0].depth, dir / "depth_right/0000.png");
  // Each right pixel, moved into the left camera, finds the same surface there.
  const DepthImage l = LoadPairDepth(left, left.pairs[0]);
  const DepthImage r = LoadPairDepth(right, right.pairs[0]);
  const DepthIntrinsics& in = l.intrinsics;
  const Pose left_from_right = left.right_from_left->inverse();
  int checked = 0, agree = 0;
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const double z = r.At(u, v);
      if (z == 0) continue;
      const Vec3 p = left_from_right * Vec3((u - in.cx) / in.fx * z, (v - in.cy) / in.fy * z, z);
      const long lu = std::lround(in.fx * p.x() / p.z() + in.cx);
      const long lv = std::lround(in.fy * p.y() / p.z() + in.cy);
      if (lu < 0 || lv < 0 || lu >= in.width || lv >= in.height) continue;
      ++checked;
      agree += std::abs(l.At(lu, lv) - p.z()) < 0.02;
    }
  }
  ASSERT_GT(checked, 20000);
  EXPECT_GT(double(agree) / checked, 0.95);
}

TEST(LrfSim, BadOptionsAndUnwritableFoldersThrow) {
  LrfSimOptions options = SmallOptions("paper");
  options.observations = 0;
  EXPECT_THROW(SampleTargetPoses(options), std::invalid_argument);
  options = SmallOptions("paper");
  options.observations = 1;
  const fs::path dir = TempDir("lrf_sim_unwritable");
  std::ofstream(dir / "file") << "x";
  EXPECT_THROW(WriteLrfSimDataset(options, dir / "file" / "sub"), IoError);
}

}  // namespace
}  // namespace calibench
