// core/lidar/swept_origin.h against the simulator's truth: the rotary-stage scanner's mirror
// (10 cm in front of the stage's axis, 5 cm above it) found from its scan alone, each return's
// estimated ray origin where the scanner's own (--lidar-viewpoints) says; scans whose rays start at
// the origin give no estimate.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/io/cloud_io.h"
#include "core/lidar/swept_origin.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

LidarCloud SimulatedCloud(LidarModel lidar, const std::string& name, bool viewpoints) {
  SimOptions sim = SimPreset("default");
  sim.lidar = lidar;
  sim.num_pairs = 2;
  sim.lidar_range_noise_m = 0.02;
  sim.lidar_viewpoints = viewpoints;
  sim.seed = 4;
  // One folder per test: ctest runs the two at once, and TempDir empties the folder it names.
  return LoadCloud(SimulateDataset(sim, test::TempDir("swept_origin_" + name)).pairs[1].cloud);
}

TEST(SweptOrigin, TheMirrorIsFoundFromTheScanAlone) {
  const LidarCloud truth = SimulatedCloud(LidarModel::kSwept2d, "swept", true);
  LidarCloud scan = truth;
  scan.viewpoint.clear();
  const std::optional<SweptOrigin> mirror = EstimateSweptOrigin(scan);
  ASSERT_TRUE(mirror);
  std::printf("%s\n", DescribeSweptOrigin(*mirror).c_str());
  EXPECT_NEAR(mirror->radial_m, 0.10, 0.005);
  EXPECT_NEAR(mirror->height_m, 0.05, 0.005);
  EXPECT_GT(mirror->gain, SweptOriginOptions{}.min_gain);
  // Each return's ray starts where the scanner's own viewpoint says, within the estimate's error.
  const std::vector<Eigen::Vector3f> estimated = SweptViewpoints(scan, *mirror);
  ASSERT_EQ(estimated.size(), truth.viewpoint.size());
  std::vector<float> apart;
  for (size_t i = 0; i < estimated.size(); ++i)
    apart.push_back((estimated[i] - truth.viewpoint[i]).norm());
  std::nth_element(apart.begin(), apart.begin() + apart.size() * 99 / 100, apart.end());
  EXPECT_LT(apart[apart.size() * 99 / 100], 0.006f);
}

TEST(SweptOrigin, RaysFromTheOriginGiveNoEstimate) {
  LidarCloud vlp16 = SimulatedCloud(LidarModel::kVlp16, "vlp16", false);
  vlp16.ring.clear();  // its cones alone, as a ring-less cloud
  EXPECT_FALSE(EstimateSweptOrigin(vlp16));
  EXPECT_FALSE(EstimateSweptOrigin(LidarCloud{}));
  std::string why;
  SweptOriginOptions bad;
  bad.fine_step_m = 0.05;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("step"), std::string::npos);
}

}  // namespace
}  // namespace calibench
