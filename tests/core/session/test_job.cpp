// The one job interface (core/session/job.h): each method's job, driven only through `Job&`,
// extracts, takes the user's rejection, solves and writes its result as its own typed steps do,
// and which job a dataset or a session is for is read from the files.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/results/result_file.h"
#include "core/session/calibration_job.h"
#include "core/session/job.h"
#include "core/session/lrf_calibration_job.h"
#include "core/sim/lrf_sim.h"
#include "tests/sim_scenes.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

// What a front end that knows no method does with a job: every pair, one rejection with its
// reason, a solve, the result file. The verdict; the file's transform in *written.
JobVerdict DriveThroughTheInterface(Job& job, const std::string& rejected_id,
                                    const std::filesystem::path& result, Pose* written) {
  int progress_calls = 0;
  job.ExtractAll([&](int, int, const std::string&) { ++progress_calls; });
  EXPECT_EQ(progress_calls, job.size());
  EXPECT_FALSE(job.record().CanUndo());
  job.SetRejected(rejected_id, true, "a smudged board");
  EXPECT_TRUE(job.record().CanUndo());
  const JobVerdict verdict = job.Calibrate();
  if (verdict.solved) {
    job.WriteResultFile(result);
    *written = LoadResult(result).cam_from_source;
  }
  return verdict;
}

void ExpectRejectedWithReason(const JobVerdict& verdict, const std::string& id) {
  int found = 0;
  for (const JobPair& pair : verdict.pairs) {
    if (pair.id != id) continue;
    ++found;
    EXPECT_EQ(pair.status, PairStatus::kRejected);
    EXPECT_EQ(pair.reason, "a smudged board");
  }
  EXPECT_EQ(found, 1) << id;
}

TEST(Job, TheLrfJobSolvesAndWritesThroughTheInterfaceAsItsOwnStepsDo) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 6;
  sim.seed = 4;
  const auto dir = test::TempDir("job_lrf");
  const auto manifest = WriteLrfSimDataset(sim, dir / "set");
  const LrfDataset dataset = LoadLrfDataset(manifest);
  const std::string rejected = dataset.pairs[2].id;

  const std::unique_ptr<LrfCalibrationJob> job = OpenLrfJob(manifest, "", {});
  Job& any = *job;
  EXPECT_EQ(any.kind(), JobKind::kLrf);
  EXPECT_EQ(any.manifest(), dataset.manifest);
  Pose written;
  const JobVerdict verdict = DriveThroughTheInterface(any, rejected, dir / "result.json", &written);
  ASSERT_TRUE(verdict.solved) << verdict.failure;
  EXPECT_TRUE(verdict.well_constrained);
  EXPECT_FALSE(verdict.input_error());
  ExpectRejectedWithReason(verdict, rejected);
  EXPECT_NE(verdict.summary.find("method refined"), std::string::npos) << verdict.summary;
  ASSERT_TRUE(verdict.ground_truth);
  EXPECT_EQ(verdict.ground_truth->matrix(), dataset.cam_from_lrf_ground_truth->matrix());

  // The LRF job's own steps, the rejection given by selection instead: the same solve, bit for
  // bit, and the result file holds it.
  LrfPipelineOptions without;
  for (const LrfPairEntry& pair : dataset.pairs)
    if (pair.id != rejected) without.pair_ids.push_back(pair.id);
  const LrfCalibrationOutcome own = CalibrateLrfDataset(dataset, without);
  ASSERT_TRUE(own.solution) << own.failure;
  EXPECT_EQ(verdict.cam_from_source.matrix(), own.solution->cam_from_lrf.matrix());
  EXPECT_EQ(verdict.covariance, own.solution->covariance);
  EXPECT_TRUE(test::MatrixNear(written.matrix(), own.solution->cam_from_lrf.matrix(), 1e-12));
  // Within the simulation's truth (the paper preset: a few mm).
  EXPECT_LT((verdict.cam_from_source.translation() - verdict.ground_truth->translation()).norm(),
            0.02);

  // The session the job's record keeps, reopened by file: the same job, the same solve.
  const auto session_file = dir / "calibench.lrf-session.json";
  any.record().SaveAs(session_file);
  EXPECT_EQ(JobKindOf("", session_file), JobKind::kLrf);
  const std::unique_ptr<LrfCalibrationJob> reopened = OpenLrfJob("", session_file, {});
  reopened->ExtractAll();
  const JobVerdict again = reopened->Calibrate();
  ASSERT_TRUE(again.solved) << again.failure;
  EXPECT_EQ(again.cam_from_source.matrix(), verdict.cam_from_source.matrix());
  ExpectRejectedWithReason(again, rejected);
  // A session is its own dataset's: another dataset named beside it is refused by name.
  const auto other = WriteLrfSimDataset(sim, dir / "other");
  try {
    OpenLrfJob(other, session_file, {});
    ADD_FAILURE() << "another dataset's session opened";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(session_file.string()), std::string::npos) << e.what();
  }
}

TEST(Job, TheLidarCameraJobSolvesAndWritesThroughTheInterfaceAsItsOwnStepsDo) {
  const auto dir = test::TempDir("job_lidar_camera");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  const std::string rejected = dataset.pairs[1].id;

  CalibrationJob job(dataset, {});
  Job& any = job;
  EXPECT_EQ(any.kind(), JobKind::kLidarCamera);
  EXPECT_EQ(JobKindOf(dataset.manifest, ""), JobKind::kLidarCamera);
  Pose written;
  const JobVerdict verdict = DriveThroughTheInterface(any, rejected, dir / "result.json", &written);
  ASSERT_TRUE(verdict.solved) << verdict.failure;
  ExpectRejectedWithReason(verdict, rejected);
  // The interface tells the typed outcome's solve, and the file holds it.
  ASSERT_TRUE(job.outcome() && job.outcome()->solution);
  EXPECT_EQ(verdict.cam_from_source.matrix(), job.outcome()->solution->cam_from_lidar.matrix());
  EXPECT_EQ(verdict.well_constrained, job.outcome()->solution->observability.well_constrained);
  EXPECT_TRUE(test::MatrixNear(written.matrix(), verdict.cam_from_source.matrix(), 1e-12));

  // `calibrate`'s own steps with the same rejection: the same solve, bit for bit.
  PairEdits edits;
  edits[rejected].rejected = true;
  const CalibrationOutcome own = CalibrateDataset(dataset, PipelineOptions{}, {}, edits);
  ASSERT_TRUE(own.solution) << own.failure;
  EXPECT_EQ(verdict.cam_from_source.matrix(), own.solution->cam_from_lidar.matrix());
  EXPECT_EQ(verdict.covariance, own.solution->covariance);
  ASSERT_TRUE(verdict.ground_truth);
  EXPECT_LT((verdict.cam_from_source.translation() - verdict.ground_truth->translation()).norm(),
            0.01);

  // Taken back through the interface: the pair is solved with again.
  any.SetRejected(rejected, false);
  const JobVerdict back = any.Calibrate();
  for (const JobPair& pair : back.pairs) {
    if (pair.id == rejected) {
      EXPECT_EQ(pair.status, PairStatus::kAccepted) << pair.reason;
    }
  }
}

TEST(Job, WhichJobIsReadFromTheSessionElseFromTheDataset) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 3;
  const auto dir = test::TempDir("job_kind");
  const auto lrf_manifest = WriteLrfSimDataset(sim, dir / "lrf");
  EXPECT_EQ(JobKindOf(lrf_manifest, ""), JobKind::kLrf);
  EXPECT_EQ(JobKindOf(lrf_manifest.parent_path(), ""), JobKind::kLrf);  // its folder
  // A LiDAR-camera session decides, whatever dataset is named beside it (its reader then checks
  // the two agree).
  Session lidar_camera;
  lidar_camera.dataset = lrf_manifest;
  SaveSession(dir / "calibench.session.json", lidar_camera);
  EXPECT_EQ(JobKindOf(lrf_manifest, dir / "calibench.session.json"), JobKind::kLidarCamera);
  SaveSession(dir / "calibench.lrf-session.json",
              NewLrfSession(LoadLrfDataset(lrf_manifest), LrfMethod::kPaperLinear));
  EXPECT_EQ(JobKindOf("", dir / "calibench.lrf-session.json"), JobKind::kLrf);
  // Nothing recognisable: the LiDAR-camera reader's to name the problem.
  EXPECT_EQ(JobKindOf(dir / "nothing-here", ""), JobKind::kLidarCamera);
  EXPECT_EQ(JobKindOf("", ""), JobKind::kLidarCamera);
  EXPECT_EQ(JobKindName(JobKind::kLrf), "2D LRF");
}

}  // namespace
}  // namespace calibench
