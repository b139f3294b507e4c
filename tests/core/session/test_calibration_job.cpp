// The pipeline job (core/session/calibration_job.h) that `calibrate`, `advise`, `watch` and the
// workbench drive: fed all at once, pair by pair or step by step, it ends where `calibrate` ends,
// and the user's rejections and brushes are its word.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <memory>
#include <set>
#include <utility>

#include "core/lidar/lidar_image.h"
#include "core/session/calibration_job.h"
#include "tests/sim_scenes.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

void ExpectSamePose(const Pose& a, const Pose& b, double tolerance, const std::string& what) {
  EXPECT_LE((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tolerance) << what;
}

// The workbench's order: every pair's files decoded once, the camera side first, then every cloud
// into the background, then each LiDAR board.
CalibrationJob StepByStep(const Dataset& dataset, const CalibrationJobOptions& options) {
  Dataset setup = dataset;
  setup.pairs.clear();
  CalibrationJob job(setup, options);
  std::vector<LidarCloud> clouds;
  for (const PairEntry& entry : dataset.pairs) {
    const int index = job.AppendPair(entry);
    std::string why;
    CameraFeatures camera;
    auto inputs = job.ReadPair(index, &camera, &why);
    EXPECT_TRUE(inputs && camera.observation) << why << camera.failure;
    clouds.push_back(std::move(inputs->cloud));
  }
  for (size_t i = 0; i < clouds.size(); ++i) job.AddToBackground(static_cast<int>(i), clouds[i]);
  for (size_t i = 0; i < clouds.size(); ++i) {
    const LidarImage image = ProjectById(clouds[i], LidarImageOptions{});
    job.DetectLidar(static_cast<int>(i), clouds[i], &image);
  }
  return job;
}

// On the scene where camera-guided completion decides pair 3 (tests/sim_scenes.h).
TEST(CalibrationJob, FedAllAtOncePairByPairOrStepByStepItEndsWhereCalibrateEnds) {
  const auto dir = test::TempDir("calibration_job");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  const CalibrationOutcome cli = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(cli.solution) << cli.failure;
  ASSERT_EQ(cli.pairs[3].board_origin.source, BoardSource::kCameraGuided);

  int progress_calls = 0;
  CalibrationJob batch(
      dataset, {}, {},
      {.detected = [&](int, int, const std::string&) { ++progress_calls; }, .iteration = {}});
  batch.DetectAll();
  const CalibrationOutcome& all = batch.Solve();
  ASSERT_TRUE(all.solution) << all.failure;
  EXPECT_EQ(progress_calls, static_cast<int>(dataset.pairs.size()));
  // The same steps in the same order: bit for bit.
  ExpectSamePose(all.solution->cam_from_lidar, cli.solution->cam_from_lidar, 0.0, "all at once");
  EXPECT_EQ(all.solution->covariance, cli.solution->covariance);
  EXPECT_EQ(all.pairs[3].board_origin.source, BoardSource::kCameraGuided);
  // And the same words on the background model (none when it was built).
  EXPECT_EQ(all.background_note, cli.background_note);
  // Every solve starts from detection: a second one is the first again.
  ExpectSamePose(batch.Solve().solution->cam_from_lidar, cli.solution->cam_from_lidar, 0.0,
                 "solved again");

  CalibrationJob steps = StepByStep(dataset, {});
  const CalibrationOutcome& stepped = steps.Solve();
  ASSERT_TRUE(stepped.solution) << stepped.failure;
  ExpectSamePose(stepped.solution->cam_from_lidar, cli.solution->cam_from_lidar, 1e-12,
                 "step by step");
  EXPECT_EQ(stepped.pairs[3].board_origin.source, BoardSource::kCameraGuided);

  // Pair by pair as a capture grows: the early pairs are detected before the background model
  // exists, and each solve starts from the last one.
  Dataset setup = dataset;
  setup.pairs.clear();
  CalibrationJobOptions growing;
  growing.warm_start = true;
  CalibrationJob live(setup, growing);
  for (const PairEntry& entry : dataset.pairs) {
    live.AddPair(entry);
    live.Solve();
  }
  const CalibrationOutcome& last = *live.outcome();
  ASSERT_TRUE(last.solution) << last.failure;
  const PoseError apart =
      ComputePoseError(last.solution->cam_from_lidar, cli.solution->cam_from_lidar);
  std::printf("pair by pair against calibrate: %.6f mm, %.6f deg\n", apart.translation_m * 1e3,
              apart.rotation_rad * kRadToDeg);
  EXPECT_LT(apart.translation_m, 1e-6);
  EXPECT_LT(apart.rotation_rad * kRadToDeg, 1e-5);
  for (size_t i = 0; i < dataset.pairs.size(); ++i)
    EXPECT_EQ(last.pairs[i].status, cli.pairs[i].status) << dataset.pairs[i].id;

  // Guidance after the solve judges the solve's pairs; the session holds their verdicts.
  const CaptureAdvice& advice = live.Advise();
  ASSERT_EQ(advice.pairs.size(), dataset.pairs.size());
  ASSERT_TRUE(advice.state);
  const Session session = live.ToSession(dir / "set");
  ASSERT_EQ(session.pairs.size(), dataset.pairs.size());
  for (size_t i = 0; i < dataset.pairs.size(); ++i)
    EXPECT_EQ(session.pairs[i].status, advice.pairs[i].status);
  ASSERT_TRUE(session.result);
  ExpectSamePose(session.result->cam_from_lidar, last.solution->cam_from_lidar, 0.0, "session");
}

TEST(CalibrationJob, TheUsersRejectionsAndBrushesAreItsWord) {
  const auto dir = test::TempDir("calibration_job_edits");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  PairEdits edits;
  edits[dataset.pairs[0].id].rejected = true;
  const CalibrationOutcome cli = CalibrateDataset(dataset, PipelineOptions{}, {}, edits);
  ASSERT_TRUE(cli.solution) << cli.failure;

  CalibrationJob job = StepByStep(dataset, {});
  job.SetRejected(dataset.pairs[0].id, true);
  const CalibrationOutcome rejected = job.Solve();
  ASSERT_TRUE(rejected.solution) << rejected.failure;
  EXPECT_EQ(rejected.pairs[0].status, PairStatus::kRejected);
  EXPECT_EQ(rejected.pairs[0].reason, kRejectedByUser);
  ExpectSamePose(rejected.solution->cam_from_lidar, cli.solution->cam_from_lidar, 1e-12,
                 "pair 0 rejected");
  // Taken back: the pair is accepted again from its planes.
  job.SetRejected(dataset.pairs[0].id, false);
  EXPECT_EQ(job.Solve().pairs[0].status, PairStatus::kAccepted);

  // A brush erased to nothing is the user's word that pair 1 has no board: it fails, and
  // camera-guided completion leaves it alone (as `calibrate --session` with that brush).
  std::string why;
  auto inputs = LoadPairInputs(dataset, dataset.pairs[1], &why);
  ASSERT_TRUE(inputs) << why;
  const LidarImage image = ProjectById(inputs->cloud, LidarImageOptions{});
  const PairEdit erased{std::vector<int>{}, image.rows, image.columns};
  job.SetBrush(dataset.pairs[1].id, erased);
  EXPECT_FALSE(job.DetectLidar(1, inputs->cloud, &image).lidar);
  const CalibrationOutcome& brushed = job.Solve();
  EXPECT_EQ(brushed.pairs[1].status, PairStatus::kFailed);
  EXPECT_FALSE(brushed.pairs[1].lidar);
  PairEdits erased_edits;
  erased_edits[dataset.pairs[1].id] = erased;
  const CalibrationOutcome cli_erased =
      CalibrateDataset(dataset, PipelineOptions{}, {}, erased_edits);
  ASSERT_TRUE(cli_erased.solution && brushed.solution);
  ExpectSamePose(brushed.solution->cam_from_lidar, cli_erased.solution->cam_from_lidar, 1e-12,
                 "pair 1 erased");
}

// The job's record of each pair (PairRecord) is what a workbench shows, with no window: the
// brush and where it came from, completion's board, the residual at the solution, the user's
// word and its undo.
TEST(CalibrationJob, ItsRecordsShowTheBrushCompletionAndUndoWithoutAWindow) {
  const auto dir = test::TempDir("calibration_job_records");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  Dataset setup = dataset;
  setup.pairs.clear();
  CalibrationJob job(setup, {});
  std::vector<LidarCloud> clouds;
  std::vector<std::shared_ptr<const LidarImage>> images;
  for (const PairEntry& entry : dataset.pairs) {
    const int index = job.AppendPair(entry);
    std::string why;
    CameraFeatures camera;
    auto inputs = job.ReadPair(index, &camera, &why);
    ASSERT_TRUE(inputs) << why;
    // Read, not yet looked for in the cloud: pending, its corners kept.
    EXPECT_EQ(job.Records()[index].status, PairStatus::kPending);
    EXPECT_TRUE(job.Records()[index].detection);
    images.push_back(std::make_shared<const LidarImage>(ProjectById(inputs->cloud, {})));
    EXPECT_EQ(job.PictureOn(index, inputs->cloud, images.back()), "");
    clouds.push_back(std::move(inputs->cloud));
  }
  for (size_t i = 0; i < clouds.size(); ++i) job.AddToBackground(static_cast<int>(i), clouds[i]);
  for (size_t i = 0; i < clouds.size(); ++i)
    job.DetectLidar(static_cast<int>(i), clouds[i], images[i].get());

  // Detected: the board's inliers drawn on each image; pair 3 (the decoy) fails, naming why.
  std::vector<PairRecord> detected = job.Records();
  ASSERT_EQ(detected.size(), dataset.pairs.size());
  EXPECT_EQ(detected[3].status, PairStatus::kFailed);
  EXPECT_FALSE(detected[3].lidar);
  EXPECT_FALSE(detected[3].lidar_failure.empty());
  EXPECT_TRUE(detected[3].brush_pixels.empty());
  for (int i : {0, 1, 2, 4}) {
    EXPECT_EQ(detected[i].status, PairStatus::kAccepted) << i << " " << detected[i].reason;
    EXPECT_EQ(detected[i].brush_origin, BrushOrigin::kDetected);
    ASSERT_TRUE(detected[i].lidar);
    std::set<int> pixels;
    for (int k : detected[i].lidar->inliers) pixels.insert(images[i]->pixel_of_point[k]);
    pixels.erase(-1);
    EXPECT_EQ(detected[i].brush_pixels, std::vector<int>(pixels.begin(), pixels.end())) << i;
  }

  // Solved and committed: completion found pair 3's board at the camera's prediction, and every
  // pair solved with has the solver's residual.
  const CalibrationOutcome solved = job.Solve();
  ASSERT_TRUE(solved.solution) << solved.failure;
  ASSERT_TRUE(job.CommitOutcome(/*own_step=*/true));
  const std::vector<PairRecord> after = job.Records(&*solved.solution, {});
  EXPECT_EQ(after[3].status, PairStatus::kAccepted) << after[3].reason;
  EXPECT_EQ(after[3].board_origin.source, BoardSource::kCameraGuided);
  EXPECT_FALSE(after[3].brush_pixels.empty());
  EXPECT_EQ(job.record().Current().pairs[3].status, PairStatus::kAccepted);
  for (const PairRecord& pair : after) {
    ASSERT_TRUE(pair.residual) << pair.id;
    EXPECT_LT(pair.residual->head<3>().norm(), 0.05) << pair.id;  // normal difference (rad)
  }

  // A brush painted over pair 1's detected board is the user's, and its undo gives the detection
  // back; a rejection and its undo the same.
  std::vector<int> painted(detected[1].brush_pixels.begin(),
                           detected[1].brush_pixels.begin() + detected[1].brush_pixels.size() / 2);
  job.SetBrush(dataset.pairs[1].id, PairEdit{painted, images[1]->rows, images[1]->columns});
  job.DetectLidar(1, clouds[1], images[1].get());
  EXPECT_EQ(job.Records()[1].brush_origin, BrushOrigin::kPainted);
  EXPECT_EQ(job.Records()[1].brush_pixels, painted);
  EXPECT_EQ(job.Records()[1].board_origin.source, BoardSource::kBrush);
  ASSERT_TRUE(job.record().Undo());
  job.DetectLidar(1, clouds[1], images[1].get());
  EXPECT_EQ(job.Records()[1].brush_origin, BrushOrigin::kDetected);
  EXPECT_EQ(job.Records()[1].brush_pixels, detected[1].brush_pixels);
  job.SetRejected(dataset.pairs[2].id, true);
  EXPECT_EQ(job.Records()[2].status, PairStatus::kRejected);
  EXPECT_EQ(job.Records()[2].reason, kRejectedByUser);
  ASSERT_TRUE(job.record().Undo());
  EXPECT_EQ(job.Records()[2].status, PairStatus::kAccepted);
  ASSERT_TRUE(job.record().Redo());
  EXPECT_EQ(job.Records()[2].status, PairStatus::kRejected);
}

// A front end edits the record from its own thread while the job solves on another (the
// workbench's ctrl+z while its worker runs the rejection's solve). The solve read the record
// once; when the word it read no longer stands the outcome is dropped, never kept as the answer
// to the record as it is now. An edit undone and redone meanwhile is the same word.
TEST(CalibrationJob, AnUndoWhileItSolvesDropsThatSolveAndTheRecordEndsWhereItStarted) {
  const auto dir = test::TempDir("calibration_job_undo_race");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  std::function<void()> during_solve;  // runs at the solve's first iteration, then no more
  CalibrationJob job(dataset, {}, {}, {.detected = {}, .iteration = [&](const IterationReport&) {
                                         if (during_solve) std::exchange(during_solve, {})();
                                       }});
  job.DetectAll();
  const CalibrationOutcome all = job.Solve();
  ASSERT_TRUE(all.solution) << all.failure;
  EXPECT_TRUE(job.CommitOutcome(/*own_step=*/true));
  const Session before = job.record().Current();
  // What it found is in the record beside the edits: the solution, each pair's verdict.
  ASSERT_TRUE(before.result);
  EXPECT_EQ(before.result->cam_from_lidar.matrix(), all.solution->cam_from_lidar.matrix());
  EXPECT_EQ(before.result->step_history.size(), all.solution->cost_history.size());
  for (size_t i = 0; i < all.pairs.size(); ++i) {
    EXPECT_EQ(before.pairs[i].status, all.pairs[i].status) << all.pairs[i].id;
    EXPECT_EQ(job.Records()[i].status, all.pairs[i].status) << all.pairs[i].id;
  }
  const std::string pair = dataset.pairs[1].id;

  job.SetRejected(pair, true);
  during_solve = [&] { ASSERT_TRUE(job.record().Undo()); };
  const CalibrationOutcome raced = job.Solve();
  ASSERT_TRUE(raced.solution);
  EXPECT_EQ(raced.pairs[1].status, PairStatus::kRejected);  // it solved the rejection it read
  EXPECT_FALSE(during_solve);                               // and the undo came meanwhile
  EXPECT_FALSE(job.CommitOutcome(/*own_step=*/false));
  EXPECT_FALSE(job.outcome());
  EXPECT_FALSE(job.advice());
  EXPECT_EQ(job.record().Current(), before);
  EXPECT_EQ(job.Records()[1].status, PairStatus::kAccepted);
  EXPECT_FALSE(job.CommitOutcome(/*own_step=*/false));  // nothing left to commit
  // Solved again, the record as it stands gives the first solve, bit for bit.
  const CalibrationOutcome& again = job.Solve();
  ASSERT_TRUE(again.solution);
  EXPECT_EQ(again.solution->cam_from_lidar.matrix(), all.solution->cam_from_lidar.matrix());
  EXPECT_EQ(again.pairs[1].status, PairStatus::kAccepted);

  // Undone and redone while it solves: the word it read stands, and so does its outcome.
  job.SetRejected(pair, true);
  during_solve = [&] {
    ASSERT_TRUE(job.record().Undo());
    ASSERT_TRUE(job.record().Redo());
  };
  job.Solve();
  EXPECT_TRUE(job.CommitOutcome(/*own_step=*/false));
  ASSERT_TRUE(job.outcome());
  EXPECT_EQ(job.outcome()->pairs[1].status, PairStatus::kRejected);
  EXPECT_EQ(job.Records()[1].status, PairStatus::kRejected);

  // The solver's settings changed while it solves: the same.
  during_solve = [&] {
    JobSettings settings = job.record().Current().settings;
    settings.huber_delta *= 2.0;
    job.SetSettings(settings);
  };
  job.Solve();
  EXPECT_FALSE(job.CommitOutcome(/*own_step=*/false));
}

// A session is the job's state on disk: resumed, its brushes, rejections (with their reasons),
// solver settings and views are the job's, before and after the pairs arrive, and ToSession
// writes them back as they were.
TEST(CalibrationJob, ResumedFromASessionItKeepsTheUsersWordAndWritesItBack) {
  const auto dir = test::TempDir("calibration_job_resume");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  std::string why;
  auto inputs = LoadPairInputs(dataset, dataset.pairs[1], &why);
  ASSERT_TRUE(inputs) << why;
  const LidarImage image = ProjectById(inputs->cloud, LidarImageOptions{});

  Session saved = NewSession(dataset);
  saved.pairs[0].status = PairStatus::kRejected;
  saved.pairs[0].reason = "pre-flight: the board is cut by the image border";
  saved.pairs[1].brush = BrushMask{image.rows, image.columns, {}};  // erased: no board there
  saved.pairs[2].brush = BrushMask{image.rows, image.columns, {5, 6}};
  saved.pairs[2].brush_from_seed = true;  // a seed's picture, not the user's word
  saved.settings.huber_delta = 0.25;
  saved.settings.max_iterations = 40;
  saved.view_json = R"({"selected_pair":"0002"})";

  // The pairs arrive after the session is resumed, one by one as a capture's.
  Dataset setup = dataset;
  setup.pairs.clear();
  CalibrationJob job(setup, {});
  job.Resume(saved);
  EXPECT_TRUE(job.HasBrush(dataset.pairs[1].id));
  EXPECT_FALSE(job.HasBrush(dataset.pairs[2].id));
  EXPECT_EQ(job.options().advise.pipeline.solver.huber_delta, 0.25);
  EXPECT_EQ(job.options().advise.pipeline.solver.max_iterations, 40);
  for (const PairEntry& entry : dataset.pairs) job.AddPair(entry);
  const CalibrationOutcome& outcome = job.Solve();
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  EXPECT_EQ(outcome.pairs[0].status, PairStatus::kRejected);
  EXPECT_EQ(outcome.pairs[0].reason, saved.pairs[0].reason);
  EXPECT_EQ(outcome.pairs[1].status, PairStatus::kFailed);  // its erased brush holds
  EXPECT_FALSE(outcome.pairs[1].lidar);

  // `calibrate --session` on the same file: the same solve.
  PipelineOptions options;
  saved.settings.Apply(&options);
  const CalibrationOutcome cli = CalibrateDataset(dataset, options, {}, EditsFromSession(saved));
  ASSERT_TRUE(cli.solution) << cli.failure;
  ExpectSamePose(outcome.solution->cam_from_lidar, cli.solution->cam_from_lidar, 1e-12,
                 "resumed job against calibrate --session");

  const Session written = job.ToSession(dataset.manifest);
  ASSERT_EQ(written.pairs.size(), saved.pairs.size());
  EXPECT_EQ(written.pairs[0].status, PairStatus::kRejected);
  EXPECT_EQ(written.pairs[0].reason, saved.pairs[0].reason);
  EXPECT_EQ(written.pairs[1].brush, saved.pairs[1].brush);
  EXPECT_FALSE(written.pairs[2].brush);  // no seed picture: the seed is the manifest's
  EXPECT_EQ(written.settings.huber_delta, 0.25);
  EXPECT_EQ(written.settings.max_iterations, 40);
  EXPECT_EQ(written.view_json, saved.view_json);
  EXPECT_EQ(EditsFromSession(written).size(), 2u);  // the rejection and the erased brush
}

}  // namespace
}  // namespace calibench
