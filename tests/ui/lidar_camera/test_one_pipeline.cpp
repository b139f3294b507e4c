// One pipeline: the workbench's controller and `calibench calibrate` compute the same calibration
// from the same dataset and the same user decisions (a painted brush, a rejected pair), bit for
// bit, because both run core/lidar_camera/pipeline.h's steps.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "tests/sim_scenes.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller.h"
#include "ui/widgets/report_job.h"

namespace calibench::ui {
namespace {

// Bit for bit: the same doubles, not merely close ones.
template <typename A, typename B>
void ExpectIdentical(const A& a, const B& b, const char* what) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  for (int r = 0; r < a.rows(); ++r)
    for (int c = 0; c < a.cols(); ++c)
      EXPECT_EQ(a(r, c), b(r, c)) << what << "(" << r << ", " << c << ")";
}

// Brushes pair 1 anew (its seed cleared, a disc painted at the board's centre) and rejects pair 2:
// the session then holds one painted brush, one rejection and two seeded pairs.
void BrushOneAndRejectOne(Controller& controller) {
  const Snapshot before = Loaded(controller);
  const PairView& pair = before.pairs[1];
  ASSERT_TRUE(pair.lidar) << pair.lidar_failure;
  const int inlier = pair.lidar->inliers[pair.lidar->inliers.size() / 2];
  const int pixel = pair.lidar_image->pixel_of_point[inlier];
  const int columns = pair.lidar_image->columns;
  controller.Apply(ClearBrush{1});
  controller.Apply(BrushStroke{1, pixel / columns, pixel % columns, 6.0f, false});
  controller.Apply(SetPairStatus{2, PairStatus::kRejected});
  controller.Apply(RunSolver{});
}

// Opens the UI dataset with its session at session_path, edits it as above and solves.
Snapshot EditedAndSolved(Controller& controller, const std::filesystem::path& session_path) {
  controller.OpenDataset(test::UiDataset(), session_path);
  BrushOneAndRejectOne(controller);
  return Loaded(controller);
}

// `calibench calibrate --session` on what the workbench autosaved, its result read back (the
// JSON writer keeps every double exactly); the command's output in *output.
LoadedResult CalibrateSession(const std::filesystem::path& session_path, std::string* output) {
  const auto out = session_path.parent_path() / "calibrated_from_session.json";
  const int code = test::RunCommand(test::CalibenchExe() + " calibrate --session " +
                                        session_path.string() + " --out " + out.string(),
                                    output);
  EXPECT_EQ(code, 0) << *output;
  return LoadResult(out);
}

TEST(OnePipeline, WorkbenchAndCalibrateAgreeBitForBit) {
  const auto dir = test::TempDir("one_pipeline");
  const auto session_path = dir / "calibench.session.json";
  Controller controller;
  const Snapshot gui = EditedAndSolved(controller, session_path);
  ASSERT_TRUE(gui.solver.result) << gui.solver.failure;
  EXPECT_NE(gui.pairs[1].brush_origin, BrushOrigin::kSeeded);
  EXPECT_EQ(gui.pairs[2].status, PairStatus::kRejected);

  // The CLI's path over what the workbench autosaved: `calibench calibrate --session`.
  const Session session = LoadSession(session_path);
  PipelineOptions options;
  session.settings.Apply(&options);
  const PairEdits edits = EditsFromSession(session);
  ASSERT_EQ(edits.size(), 2u);  // the painted brush and the rejection
  const CalibrationOutcome cli = CalibrateDataset(LoadDataset(session.dataset), options, {}, edits);
  ASSERT_TRUE(cli.solution) << cli.failure;

  ExpectIdentical(gui.solver.result->cam_from_lidar.matrix(), cli.solution->cam_from_lidar.matrix(),
                  "cam_from_lidar");
  ExpectIdentical(gui.solver.result->covariance, cli.solution->covariance, "covariance");
  EXPECT_EQ(gui.solver.result->iterations, cli.solution->iterations);
  ASSERT_EQ(gui.pairs.size(), cli.pairs.size());
  for (size_t i = 0; i < gui.pairs.size(); ++i) {
    EXPECT_EQ(gui.pairs[i].status, cli.pairs[i].status) << gui.pairs[i].id;
    EXPECT_EQ(gui.pairs[i].reason, cli.pairs[i].reason) << gui.pairs[i].id;
  }

  // The workbench's Export and `calibrate --out` write the same file.
  const auto exported = dir / "exported.json";
  controller.Apply(ExportResult{exported});
  controller.WaitIdle();
  const auto written = dir / "calibrated.json";
  WriteResult(written, cli, options.solver);
  EXPECT_EQ(test::ReadFileBytes(exported), test::ReadFileBytes(written));
}

TEST(OnePipeline, CalibrateWithTheSessionFlagMatchesTheWorkbench) {
  const auto dir = test::TempDir("one_pipeline_cli");
  const auto session_path = dir / "calibench.session.json";
  Controller controller;
  const Snapshot gui = EditedAndSolved(controller, session_path);
  ASSERT_TRUE(gui.solver.result) << gui.solver.failure;

  std::string output;
  const LoadedResult cli = CalibrateSession(session_path, &output);
  EXPECT_NE(output.find("rejected"), std::string::npos) << output;
  // Through the result file's text: the JSON writer keeps every double exactly.
  ExpectIdentical(cli.cam_from_source.matrix(), gui.solver.result->cam_from_lidar.matrix(),
                  "cam_from_lidar");
  ExpectIdentical(cli.covariance, gui.solver.result->covariance, "covariance");
}

// A scene where camera-guided completion decides a pair (tests/sim_scenes.h: a board-sized decoy
// sheet beside the board in pair 3's cloud, so that detection fails it naming both): the
// workbench's solve completes it as `calibrate` does, a second solve starts again from detection,
// and the session it saved calibrates on the command line to the same transform.
TEST(OnePipeline, CameraGuidedCompletionRunsInTheWorkbenchAsInCalibrate) {
  const auto dir = test::TempDir("one_pipeline_completion");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  PipelineOptions without_completion;
  without_completion.camera_guided = false;
  const CalibrationOutcome alone = CalibrateDataset(dataset, without_completion);
  const CalibrationOutcome cli = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(alone.solution && cli.solution) << alone.failure << cli.failure;
  // Completion matters here: without it pair 3 is lost and the transform is another.
  ASSERT_EQ(alone.pairs[3].status, PairStatus::kFailed);
  ASSERT_EQ(cli.pairs[3].status, PairStatus::kAccepted) << cli.pairs[3].reason;
  ASSERT_EQ(cli.pairs[3].board_origin.source, BoardSource::kCameraGuided);
  const double moved_m =
      (alone.solution->cam_from_lidar.translation() - cli.solution->cam_from_lidar.translation())
          .norm();
  EXPECT_GT(moved_m, 1e-6);
  std::printf("completion moves the translation by %.3f mm\n", moved_m * 1e3);

  const auto session_path = dir / "calibench.session.json";
  Controller controller;
  controller.OpenDataset(dataset.manifest, session_path);
  controller.WaitIdle();
  EXPECT_EQ(controller.GetSnapshot().pairs[3].status, PairStatus::kFailed);  // detection alone
  for (int solve = 0; solve < 2; ++solve) {  // the second starts from detection again
    controller.Apply(RunSolver{});
    const Snapshot gui = Loaded(controller);
    ASSERT_TRUE(gui.solver.result) << gui.solver.failure;
    EXPECT_EQ(gui.pairs[3].status, PairStatus::kAccepted) << gui.pairs[3].reason;
    EXPECT_EQ(gui.pairs[3].board_origin.source, BoardSource::kCameraGuided);
    const Mat4 difference =
        gui.solver.result->cam_from_lidar.matrix() - cli.solution->cam_from_lidar.matrix();
    EXPECT_LT(difference.cwiseAbs().maxCoeff(), 1e-9) << "solve " << solve;
  }
  std::string output;
  const Mat4 difference = CalibrateSession(session_path, &output).cam_from_source.matrix() -
                          cli.solution->cam_from_lidar.matrix();
  EXPECT_LT(difference.cwiseAbs().maxCoeff(), 1e-9);
}

// A camera file with its intrinsics' covariance: the workbench's σ carries it as `calibrate`'s
// does (AddIntrinsicsUncertainty after the solve, in both), to the bit.
TEST(OnePipeline, TheIntrinsicsCovarianceIsInTheWorkbenchsSigmaAsInTheCommandLines) {
  const auto dir = test::TempDir("one_pipeline_intrinsics");
  std::filesystem::copy(test::UiDataset().parent_path(), dir / "set",
                        std::filesystem::copy_options::recursive);
  const auto manifest = dir / "set" / test::UiDataset().filename();
  nlohmann::json root;
  std::ifstream(manifest) >> root;
  std::vector<double> covariance(81, 0.0);
  const double sigma[] = {3.0, 3.0, 2.0, 2.0, 0.002, 0.004, 0.0003, 0.0003, 0.0};
  for (int i = 0; i < 9; ++i) covariance[i * 9 + i] = sigma[i] * sigma[i];
  root["camera"]["intrinsics_covariance"] = covariance;
  std::ofstream(manifest) << root.dump(1);

  Controller controller;
  controller.OpenDataset(manifest, dir / "s.json");
  controller.WaitIdle();
  controller.Apply(RunSolver{});
  const Snapshot gui = Loaded(controller);
  ASSERT_TRUE(gui.solver.result) << gui.solver.failure;
  EXPECT_FALSE(gui.solver.result->intrinsics_covariance.isZero(0.0));
  const CalibrationOutcome cli = CalibrateDataset(LoadDataset(manifest), PipelineOptions{});
  ASSERT_TRUE(cli.solution) << cli.failure;
  ExpectIdentical(gui.solver.result->covariance, cli.solution->covariance, "covariance");
  ExpectIdentical(gui.solver.result->intrinsics_covariance, cli.solution->intrinsics_covariance,
                  "intrinsics_covariance");
}

// File → Report… runs `calibench report` on the autosaved session: the report carries the
// workbench's rejection and its result; a session without a result is refused, in words.
TEST(OnePipeline, TheWorkbenchsReportIsTheCommandLinesOnTheSession) {
  const auto dir = test::TempDir("one_pipeline_report");
  const auto session_path = dir / "calibench.session.json";
  Controller controller;
  const Snapshot gui = EditedAndSolved(controller, session_path);
  ASSERT_TRUE(gui.solver.result) << gui.solver.failure;
  {
    ReportJob job(test::CalibenchExe(), session_path, dir / "report.html");
    while (!job.Done()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_EQ(job.exit_code(), 0) << job.output();
    EXPECT_NE(job.output().find("wrote " + (dir / "report.html").string()), std::string::npos);
    // No note that the result differs from the re-solve: the session's options were used.
    EXPECT_EQ(job.output().find("differs from a re-solve"), std::string::npos) << job.output();
  }
  const std::string html = test::ReadFileBytes(dir / "report.html");
  const std::string rejected = "<tr data-pair=\"" + gui.pairs[2].id + "\"";
  const size_t row = html.find(rejected);
  ASSERT_NE(row, std::string::npos);
  EXPECT_NE(html.substr(row, 200).find("rejected"), std::string::npos) << html.substr(row, 200);

  Session unsolved = LoadSession(session_path);
  unsolved.result.reset();
  SaveSession(dir / "unsolved.session.json", unsolved);
  ReportJob refused(test::CalibenchExe(), dir / "unsolved.session.json", dir / "none.html");
  while (!refused.Done()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_NE(refused.exit_code(), 0);
  EXPECT_NE(refused.output().find("the session has no result yet"), std::string::npos)
      << refused.output();
  EXPECT_FALSE(std::filesystem::exists(dir / "none.html"));
}

TEST(OnePipeline, RenderSolveAndCalibrateWriteTheSameTransform) {
  const auto dir = test::TempDir("one_pipeline_render");
  // A copy of the dataset's manifest in its own folder; render writes the session only where
  // --save-session says.
  const Dataset dataset = LoadDataset(test::UiDataset());
  const auto manifest = dir / "dataset.json";
  SaveDataset(manifest, dataset);
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " render --dataset " + manifest.string() +
                                 " --solve --view camera --size 320x240 --out " +
                                 (dir / "camera.png").string() + " --save-session " +
                                 (dir / "render.session.json").string(),
                             &output),
            0)
      << output;
  EXPECT_FALSE(std::filesystem::exists(dir / "calibench.session.json"));
  const Session session = LoadSession(dir / "render.session.json");
  ASSERT_TRUE(session.result);
  const auto out = dir / "result.json";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + manifest.string() +
                                 " --out " + out.string(),
                             &output),
            0)
      << output;
  const LoadedResult cli = LoadResult(out);
  ExpectIdentical(cli.cam_from_source.matrix(), session.result->cam_from_lidar.matrix(),
                  "cam_from_lidar");
  ExpectIdentical(cli.covariance, session.result->covariance, "covariance");
}

}  // namespace
}  // namespace calibench::ui
