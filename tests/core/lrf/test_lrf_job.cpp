// The LRF method's job (core/lrf/lrf_job.h): pair by pair (the workbench's order) it ends where
// all at once (`lrf-calibrate`) ends, and the user's rejections are its word.
#include <gtest/gtest.h>

#include "core/lrf/lrf_job.h"
#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(LrfJob, PairByPairOrAllAtOnceItSolvesTheSameWithTheUsersRejections) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 6;
  sim.seed = 2;
  const LrfDataset dataset = LoadLrfDataset(WriteLrfSimDataset(sim, test::TempDir("lrf_job")));

  LrfCalibrationJob all(dataset, {});
  int progress_calls = 0;
  all.ExtractAll([&](int, int, const std::string&) { ++progress_calls; });
  EXPECT_EQ(progress_calls, 6);
  const LrfCalibrationOutcome every = all.Solve();
  ASSERT_TRUE(every.solution && every.solution->ok) << every.failure;
  ASSERT_TRUE(dataset.cam_from_lrf_ground_truth);
  EXPECT_LT((every.solution->cam_from_lrf.translation() -
             dataset.cam_from_lrf_ground_truth->translation())
                .norm(),
            0.02);

  // Pair by pair, a rejection made before the last pair arrives.
  LrfCalibrationJob stepped(dataset, {});
  EXPECT_EQ(stepped.ExtractedPairs()[0].status, PairStatus::kPending);
  stepped.SetRejected(dataset.pairs[4].id, true);
  for (int i = 0; i < stepped.size(); ++i) stepped.ExtractPair(i);
  const LrfCalibrationOutcome rejected = stepped.Solve();
  ASSERT_TRUE(rejected.solution) << rejected.failure;
  EXPECT_EQ(rejected.pairs[4].status, PairStatus::kRejected);
  EXPECT_EQ(rejected.pairs[4].reason, kRejectedByUser);
  LrfPipelineOptions without;
  for (const LrfPairEntry& pair : dataset.pairs)
    if (pair.id != dataset.pairs[4].id) without.pair_ids.push_back(pair.id);
  const LrfCalibrationOutcome cli = CalibrateLrfDataset(dataset, without);
  ASSERT_TRUE(cli.solution) << cli.failure;
  EXPECT_EQ(rejected.solution->cam_from_lrf.matrix(), cli.solution->cam_from_lrf.matrix());

  // Taken back: the job is every pair's again, bit for bit.
  stepped.SetRejected(dataset.pairs[4].id, false);
  const LrfCalibrationOutcome again = stepped.Solve();
  ASSERT_TRUE(again.solution);
  EXPECT_EQ(again.solution->cam_from_lrf.matrix(), every.solution->cam_from_lrf.matrix());
}

}  // namespace
}  // namespace calibench
