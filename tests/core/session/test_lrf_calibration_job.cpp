// The LRF method's job (core/session/lrf_calibration_job.h): pair by pair (the workbench's order)
// it ends where all at once (`lrf-calibrate`) ends; its record (the LRF session) is the user's
// word, with undo, and its file is told from a LiDAR-camera session's.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "core/session/lrf_calibration_job.h"
#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

// `call` must throw an IoError whose message holds every one of `words`.
template <typename Call>
void ExpectIoError(Call call, const std::vector<std::string>& words) {
  try {
    call();
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& e) {
    for (const std::string& word : words)
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
  }
}

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

// The record is the user's word: a rejection and a method are undo steps, a solve amends the step
// it follows, and a job made from the saved session solves as the one that saved it, bit for bit.
TEST(LrfCalibrationJob, ItsRecordIsTheUsersWordWithUndoAndASavedSessionSolvesTheSame) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 6;
  sim.seed = 2;
  const LrfDataset dataset =
      LoadLrfDataset(WriteLrfSimDataset(sim, test::TempDir("lrf_job_record")));
  LrfCalibrationJob job(dataset, {});
  job.ExtractAll();
  const LrfCalibrationOutcome every = job.Solve();
  ASSERT_TRUE(every.solution && every.solution->ok) << every.failure;
  ASSERT_TRUE(job.record().Current().result);
  EXPECT_EQ(*job.record().Current().result, SessionResultFromLrf(*every.solution));
  EXPECT_FALSE(job.record().CanUndo());  // a solve is no edit

  const std::string& id = dataset.pairs[3].id;
  job.SetRejected(id, true);
  job.SetMethod(LrfMethod::kPaperLinear);
  EXPECT_EQ(job.options().solver.method, LrfMethod::kPaperLinear);
  const LrfCalibrationOutcome edited = job.Solve();
  ASSERT_TRUE(edited.solution && edited.solution->ok) << edited.failure;
  EXPECT_EQ(edited.solution->method, LrfMethod::kPaperLinear);
  EXPECT_EQ(edited.pairs[3].status, PairStatus::kRejected);
  const Session saved = job.record().Current();
  EXPECT_EQ(saved.lrf_method, "paper-linear");
  EXPECT_EQ(saved.pairs[3].status, PairStatus::kRejected);
  EXPECT_EQ(saved.pairs[0].status, PairStatus::kPending);  // extraction's verdicts are not kept

  // The saved session, through its file, in a new job: the same solve.
  const auto file = test::TempDir("lrf_job_record_session") / "calibench.lrf-session.json";
  SaveSession(file, saved);
  EXPECT_TRUE(IsLrfSession(file));
  LrfSessionWithDataset reopened = LoadLrfSessionWithDataset(file);
  EXPECT_EQ(reopened.session, saved);
  LrfCalibrationJob again(reopened.dataset, {}, reopened.session);
  again.ExtractAll();
  const LrfCalibrationOutcome same = again.Solve();
  ASSERT_TRUE(same.solution);
  EXPECT_EQ(same.solution->cam_from_lrf.matrix(), edited.solution->cam_from_lrf.matrix());
  EXPECT_EQ(same.solution->covariance, edited.solution->covariance);

  // Two undos: the method, then the rejection; the job solves as at first, bit for bit.
  ASSERT_TRUE(job.record().Undo());
  EXPECT_EQ(job.options().solver.method, LrfMethod::kRefined);
  EXPECT_EQ(job.Rejected(), std::set<std::string>{id});
  ASSERT_TRUE(job.record().Undo());
  EXPECT_TRUE(job.Rejected().empty());
  EXPECT_FALSE(job.record().CanUndo());
  const LrfCalibrationOutcome undone = job.Solve();
  ASSERT_TRUE(undone.solution);
  EXPECT_EQ(undone.solution->cam_from_lrf.matrix(), every.solution->cam_from_lrf.matrix());
  ASSERT_TRUE(job.record().Redo());
  EXPECT_EQ(job.Rejected(), std::set<std::string>{id});
}

// The file tells the two kinds apart: each reader refuses the other's session, naming the file and
// what opens it; a method the LRF solver does not have is the file's error.
TEST(LrfSession, EachReaderRefusesTheOtherKindOfSession) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 3;
  const auto folder = test::TempDir("lrf_session_kinds");
  const LrfDataset dataset = LoadLrfDataset(WriteLrfSimDataset(sim, folder));
  const auto lrf_file = folder / "calibench.lrf-session.json";
  SaveSession(lrf_file, NewLrfSession(dataset, LrfMethod::kRefined));
  EXPECT_EQ(DefaultLrfSessionPath(dataset.manifest), lrf_file);
  ExpectIoError([&] { LoadSessionWithDataset(lrf_file); },
                {lrf_file.string(), "2D LRF session", "lrf-calibrate --session"});

  Session lidar_camera;
  lidar_camera.dataset = dataset.manifest;
  const auto lc_file = folder / "calibench.session.json";
  SaveSession(lc_file, lidar_camera);
  EXPECT_FALSE(IsLrfSession(lc_file));
  ExpectIoError([&] { LoadLrfSessionWithDataset(lc_file); },
                {lc_file.string(), "not a 2D LRF one"});

  std::string text = SessionToJson(NewLrfSession(dataset, LrfMethod::kRefined), lrf_file);
  text.replace(text.find("\"refined\""), 9, "\"fastest\"");
  ExpectIoError([&] { SessionFromJson(text, lrf_file); },
                {lrf_file.string(), "lrf_method", "fastest"});
}

}  // namespace
}  // namespace calibench
