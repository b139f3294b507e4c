// The feature cache of `watch`: features read back are the features written, a line cut short by
// a kill is ignored, and a pair whose file changed is detected again; a ring-less cloud's fit
// under the other candidate model comes back with it.
#include <gtest/gtest.h>

#include <fstream>

#include "core/session/feature_cache.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

TEST(FeatureCache, ReadsBackWhatItWroteAndDropsWhatNoLongerHolds) {
  const fs::path dir = test::TempDir("feature_cache");
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 3;
  const Dataset dataset = SimulateDataset(sim, dir / "sim");
  const fs::path cache = FeatureCachePath(dir / "calibench.session.json");
  EXPECT_EQ(cache, dir / "calibench.session.features.jsonl");
  FeatureCacheWriter writer(cache);
  std::vector<PairFeatures> written;
  for (const PairEntry& pair : dataset.pairs) {
    written.push_back(ExtractPairFeatures(dataset, pair, PipelineOptions{}));
    ASSERT_TRUE(written.back().lidar && written.back().camera) << written.back().reason;
    writer.Append(pair, written.back());
  }
  // A later line of a pair replaces its earlier one.
  PairFeatures failed = written[2];
  failed.status = PairStatus::kFailed;
  failed.reason = "LiDAR board disagrees with the camera's";
  writer.Append(dataset.pairs[2], failed);
  // A line cut short by a kill.
  std::ofstream(cache, std::ios::app) << R"({"format": "calibench.features.v4", "id": "00)";

  int skipped = -1;
  auto read = LoadFeatureCache(cache, &skipped);
  EXPECT_EQ(skipped, 1);
  ASSERT_EQ(read.size(), 3u);
  const PairFeatures& back = read.at(dataset.pairs[0].id).features;
  EXPECT_EQ(read.at(dataset.pairs[0].id).entry.cloud, dataset.pairs[0].cloud);
  EXPECT_EQ(back.status, written[0].status);
  EXPECT_EQ(back.lidar->plane.Coefficients(), written[0].lidar->plane.Coefficients());
  EXPECT_EQ(back.lidar->covariance, written[0].lidar->covariance);
  EXPECT_EQ(back.lidar->inliers, written[0].lidar->inliers);
  // The sums the LiDAR's noise is learned from (a fit along the rays), exactly.
  ASSERT_GT(written[0].lidar->range_moments.count, 0);
  EXPECT_EQ(back.lidar->range_moments.count, written[0].lidar->range_moments.count);
  EXPECT_EQ(back.lidar->range_moments.sum_z_e2, written[0].lidar->range_moments.sum_z_e2);
  EXPECT_EQ(back.lidar->range_moments.min_z, written[0].lidar->range_moments.min_z);
  EXPECT_EQ(back.lidar->edge_points.size(), written[0].lidar->edge_points.size());
  EXPECT_EQ(back.camera->cam_from_board.matrix(), written[0].camera->cam_from_board.matrix());
  EXPECT_EQ(back.camera->pose_covariance, written[0].camera->pose_covariance);
  // The corners come back exactly (the joint refinement of the intrinsics poses them again).
  ASSERT_FALSE(written[0].camera->corners.pixels.empty());
  EXPECT_EQ(back.camera->corners.pixels, written[0].camera->corners.pixels);
  EXPECT_EQ(back.camera->corners.board_points, written[0].camera->corners.board_points);
  EXPECT_EQ(back.camera->corners.ids, written[0].camera->corners.ids);
  EXPECT_EQ(back.board_origin.source, written[0].board_origin.source);
  EXPECT_EQ(read.at(dataset.pairs[2].id).features.status, PairStatus::kFailed);
  EXPECT_EQ(read.at(dataset.pairs[2].id).features.reason, failed.reason);

  // Pair 1's image rewritten: its lines no longer hold.
  const std::string image = test::ReadFileBytes(dataset.pairs[1].image);
  std::ofstream(dataset.pairs[1].image, std::ios::binary) << image << " ";
  read = LoadFeatureCache(cache, &skipped);
  EXPECT_EQ(read.count(dataset.pairs[1].id), 0u);
  EXPECT_EQ(skipped, 2);
  EXPECT_TRUE(LoadFeatureCache(dir / "none.jsonl").empty());
}

// A ring-less cloud's pair carries the other candidate model's fit
// (LidarPlaneFit::alternative) for the held-out pairs to choose from: it comes back exactly, so a
// session reopened chooses as the first run did.
TEST(FeatureCache, AnAlternativeModelsFitComesBack) {
  const fs::path dir = test::TempDir("feature_cache_alternative");
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 1;
  sim.board_only_clouds = true;
  const Dataset dataset = SimulateDataset(sim, dir / "sim");
  const PairFeatures written = ExtractPairFeatures(dataset, dataset.pairs[0], PipelineOptions{});
  ASSERT_TRUE(written.lidar) << written.reason;
  ASSERT_TRUE(written.lidar->alternative);
  EXPECT_EQ(written.lidar->lidar_model.geometry, LidarGeometry::kSegment);
  EXPECT_EQ(written.lidar->alternative->lidar_model.geometry, LidarGeometry::kNonRepetitive);
  EXPECT_GT(written.lidar->alternative->range_moments.count, 0);
  const fs::path cache = dir / "features.jsonl";
  FeatureCacheWriter(cache).Append(dataset.pairs[0], written);
  const auto read = LoadFeatureCache(cache);
  ASSERT_EQ(read.size(), 1u);
  const LidarPlaneFit& back = *read.at(dataset.pairs[0].id).features.lidar;
  ASSERT_TRUE(back.alternative);
  EXPECT_EQ(back.alternative->plane.Coefficients(),
            written.lidar->alternative->plane.Coefficients());
  EXPECT_EQ(back.alternative->covariance, written.lidar->alternative->covariance);
  EXPECT_EQ(back.alternative->ring_bias_covariance,
            written.lidar->alternative->ring_bias_covariance);
  EXPECT_EQ(back.alternative->lidar_model.why, written.lidar->alternative->lidar_model.why);
  EXPECT_EQ(back.alternative->range_moments.sum_z_e2,
            written.lidar->alternative->range_moments.sum_z_e2);
  // With a model the user forces there is nothing to choose: no alternative.
  PipelineOptions forced;
  forced.lidar_model = LidarGeometry::kSegment;
  EXPECT_FALSE(ExtractPairFeatures(dataset, dataset.pairs[0], forced).lidar->alternative);
}

}  // namespace
}  // namespace calibench
