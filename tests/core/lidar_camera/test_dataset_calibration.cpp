// CalibrateDataset one step at a time (core/lidar_camera/dataset_calibration.h), as the
// workbench's rig solve runs it between the user's edits: each step extracts at most one pair per
// thread, the solve is a step of its own, and the outcome is the one-call calibration's, bit for
// bit, whatever the thread count.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "core/lidar_camera/dataset_calibration.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(DatasetCalibration, StepsTakeAPairPerThreadAndGiveTheOneCallOutcome) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 9;
  sim.seed = 11;
  const Dataset dataset = SimulateDataset(sim, test::TempDir("dataset_calibration") / "sim");
  ASSERT_EQ(dataset.pairs.size(), 9u);

  PipelineOptions two_threads;
  two_threads.threads = 2;
  std::vector<int> done_seen;
  std::set<std::string> pairs_seen;
  DatasetCalibration calibration(
      dataset, two_threads, {},
      [&](int done, int total, const std::string& pair) {
        EXPECT_EQ(total, 9);
        done_seen.push_back(done);
        pairs_seen.insert(pair);
      },
      /*pairs_per_thread=*/1);
  int steps = 1;  // the last Step() runs too
  std::vector<size_t> extracted_after_step;
  while (calibration.Step()) {
    ++steps;
    extracted_after_step.push_back(done_seen.size());
  }
  // The background, ceil(9 / 2) = 5 chunks of at most 2 pairs, the solve.
  EXPECT_EQ(steps, 1 + 5 + 1);
  ASSERT_EQ(extracted_after_step.size(), 6u);
  EXPECT_EQ(extracted_after_step[0], 0u) << "the first step builds the background only";
  for (size_t k = 1; k < extracted_after_step.size(); ++k)
    EXPECT_LE(extracted_after_step[k] - extracted_after_step[k - 1], 2u) << "step " << k;
  EXPECT_EQ(done_seen.size(), 9u);
  for (size_t k = 0; k < done_seen.size(); ++k)
    EXPECT_EQ(done_seen[k], static_cast<int>(k) + 1) << "progress counts over the whole dataset";
  EXPECT_EQ(pairs_seen.size(), 9u);
  EXPECT_FALSE(calibration.Step()) << "nothing is left";
  const CalibrationOutcome stepped = calibration.Take();

  PipelineOptions one_thread;
  one_thread.threads = 1;
  const CalibrationOutcome one_call = CalibrateDataset(dataset, one_thread);
  ASSERT_TRUE(stepped.solution && one_call.solution) << stepped.failure << one_call.failure;
  EXPECT_EQ(stepped.solution->cam_from_lidar.matrix(), one_call.solution->cam_from_lidar.matrix());
  EXPECT_EQ(stepped.solution->covariance, one_call.solution->covariance);
  ASSERT_EQ(stepped.pairs.size(), one_call.pairs.size());
  for (size_t i = 0; i < stepped.pairs.size(); ++i) {
    EXPECT_EQ(stepped.pairs[i].id, dataset.pairs[i].id) << "features in the dataset's order";
    EXPECT_EQ(stepped.pairs[i].status, one_call.pairs[i].status) << i;
    ASSERT_EQ(stepped.pairs[i].lidar.has_value(), one_call.pairs[i].lidar.has_value()) << i;
    if (stepped.pairs[i].lidar) {
      EXPECT_EQ(stepped.pairs[i].lidar->inliers, one_call.pairs[i].lidar->inliers) << i;
    }
  }
  EXPECT_EQ(stepped.background_note, one_call.background_note);
  ASSERT_TRUE(dataset.cam_from_lidar_ground_truth.has_value());
  const PoseError error =
      ComputePoseError(stepped.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
  EXPECT_LT(error.translation_m, 0.02);
  EXPECT_LT(error.rotation_rad, 0.5 * kDegToRad);

  // By default (CalibrateDataset) extraction is one step: the background, the pairs, the solve.
  DatasetCalibration in_one(dataset, two_threads);
  int default_steps = 1;
  while (in_one.Step()) ++default_steps;
  EXPECT_EQ(default_steps, 3);
  EXPECT_EQ(in_one.Take().solution->cam_from_lidar.matrix(),
            one_call.solution->cam_from_lidar.matrix());
}

}  // namespace
}  // namespace calibench
