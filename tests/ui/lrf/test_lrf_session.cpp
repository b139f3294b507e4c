// The LRF workbench's session (core/session/lrf_calibration_job.h): autosaved beside the manifest
// as the user edits, resumed when the manifest opens again, undone and redone, read by
// `calibench lrf-calibrate --session` to the same result; a session that does not open is moved
// aside, never lost; each kind of session is refused by the other kind's readers.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/results/result_file.h"
#include "core/session/lrf_calibration_job.h"
#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"
#include "ui/lrf/controller.h"

namespace calibench::ui {
namespace {

// Six "paper" observations in a folder of the test's own (the session is written beside them).
std::filesystem::path LrfDatasetIn(const std::string& folder) {
  LrfSimOptions options = *LrfSimPreset("paper");
  options.observations = 6;
  options.seed = 2;  // all six observations extract
  return WriteLrfSimDataset(options, test::TempDir(folder));
}

void OpenAndWait(LrfController& controller, const std::filesystem::path& manifest,
                 ExistingSession use = ExistingSession::kResume) {
  ASSERT_TRUE(controller.Open(manifest, use)) << controller.GetSnapshot().status_line;
  controller.WaitIdle();
}

bool Says(const std::string& text, const std::string& words) {
  return text.find(words) != std::string::npos;
}

TEST(LrfSession, TheWorkbenchSavesItsWordAndResumesItWhereTheCommandLineReadsItToo) {
  const std::filesystem::path manifest = LrfDatasetIn("lrf_session_resume");
  const std::filesystem::path session_file = DefaultLrfSessionPath(manifest);
  LrfSolution solved;
  {
    LrfController controller;
    OpenAndWait(controller, manifest);
    EXPECT_EQ(controller.GetSnapshot().session_path, session_file);
    ASSERT_TRUE(std::filesystem::exists(session_file));  // a new session is a file at once
    controller.Apply(LrfSetPairStatus{2, PairStatus::kRejected});
    controller.Apply(LrfSetMethod{LrfMethod::kPaperLinear});
    controller.Apply(LrfSelectPair{4});
    controller.Apply(LrfRunSolver{});
    controller.WaitIdle();
    const LrfSnapshot s = controller.GetSnapshot();
    ASSERT_TRUE(s.solver.solution) << s.solver.failure;
    EXPECT_TRUE(s.save_error.empty()) << s.save_error;
    solved = *s.solver.solution;

    // Undo takes back the method (the solve it had goes with it), redo brings both back.
    LrfSnapshot undone;
    controller.Apply(LrfUndo{});
    controller.WaitIdle();
    undone = controller.GetSnapshot();
    EXPECT_EQ(undone.solver.method, LrfMethod::kRefined);
    EXPECT_EQ(undone.pairs[2].status, PairStatus::kRejected);
    EXPECT_FALSE(undone.solver.solution);  // that step was never solved
    EXPECT_EQ(LoadSession(session_file).lrf_method, "refined");
    controller.Apply(LrfRedo{});
    controller.WaitIdle();
    undone = controller.GetSnapshot();
    EXPECT_EQ(undone.solver.method, LrfMethod::kPaperLinear);
    ASSERT_TRUE(undone.solver.solution);
    EXPECT_EQ(undone.solver.solution->cam_from_lrf.matrix(), solved.cam_from_lrf.matrix());
    EXPECT_EQ(LoadSession(session_file).lrf_method, "paper-linear");

    // While it is open here, a second workbench may not open it.
    LrfController second;
    EXPECT_FALSE(second.Open(manifest));
    EXPECT_TRUE(Says(second.GetSnapshot().status_line, "open in another Calibench workbench"))
        << second.GetSnapshot().status_line;
  }
  // The file holds the user's word and the last solve.
  const Session saved = LoadSession(session_file);
  EXPECT_EQ(saved.lrf_method, "paper-linear");
  ASSERT_EQ(saved.pairs.size(), 6u);
  EXPECT_EQ(saved.pairs[2].status, PairStatus::kRejected);
  EXPECT_EQ(saved.pairs[2].reason, kRejectedByUser);
  EXPECT_TRUE(Says(saved.view_json, saved.pairs[4].id)) << saved.view_json;
  ASSERT_TRUE(saved.result);
  EXPECT_EQ(saved.result->cam_from_lidar.matrix(), solved.cam_from_lrf.matrix());

  // Opened again: resumed as it was left — the rejection, the method, the pair, the solve.
  LrfController controller;
  OpenAndWait(controller, manifest);
  LrfSnapshot s = controller.GetSnapshot();
  EXPECT_TRUE(Says(s.session_note, "resumed the session")) << s.session_note;
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  EXPECT_EQ(s.solver.method, LrfMethod::kPaperLinear);
  EXPECT_EQ(s.selected, 4);
  ASSERT_TRUE(s.solver.solution) << s.solver.failure;
  EXPECT_EQ(s.solver.solution->cam_from_lrf.matrix(), solved.cam_from_lrf.matrix());

  // The command line reads the same session to the same transform, bit for bit.
  const auto out = test::TempDir("lrf_session_resume_out") / "result.json";
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " lrf-calibrate --session " +
                                 session_file.string() + " --out " + out.string(),
                             &output),
            0)
      << output;
  EXPECT_TRUE(Says(output, "paper-linear")) << output;
  EXPECT_TRUE(test::MatrixNear(LoadResult(out).cam_from_source.matrix(),
                               solved.cam_from_lrf.matrix(), 0.0));
  // `calibrate --session` reads the LRF session too, through the same job interface: the same
  // file, the same transform.
  const auto through_calibrate = out.parent_path() / "calibrate.json";
  const auto calibrate_page = out.parent_path() / "calibrate.html";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --session " +
                                 session_file.string() + " --out " + through_calibrate.string() +
                                 " --report " + calibrate_page.string(),
                             &output),
            0)
      << output;
  EXPECT_TRUE(Says(output, "paper-linear")) << output;
  {  // its report is the LRF method's, of the session's solve
    std::ifstream in(calibrate_page);
    const std::string html((std::istreambuf_iterator<char>(in)), {});
    EXPECT_TRUE(Says(html, "method paper-linear")) << output;
    EXPECT_TRUE(Says(html, session_file.string())) << output;
  }
  EXPECT_TRUE(test::MatrixNear(LoadResult(through_calibrate).cam_from_source.matrix(),
                               solved.cam_from_lrf.matrix(), 0.0));
  // Naming another method than the session's is refused.
  EXPECT_NE(test::RunCommand(test::CalibenchExe() + " lrf-calibrate --session " +
                                 session_file.string() + " --method refined",
                             &output),
            0);
  EXPECT_TRUE(Says(output, "--method refined disagrees")) << output;
  // `report --session` re-solves with the session's rejection and method: the result's transform
  // (no "differs from a re-solve" note), pair 2 listed as the user rejected it.
  const auto page = out.parent_path() / "report.html";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " report --session " + session_file.string() +
                                 " --result " + out.string() + " --out " + page.string(),
                             &output),
            0)
      << output;
  EXPECT_FALSE(Says(output, "differs from a re-solve")) << output;
  std::ifstream in(page);
  const std::string html((std::istreambuf_iterator<char>(in)), {});
  EXPECT_TRUE(Says(html, "method paper-linear")) << output;
  EXPECT_TRUE(Says(html, "rejected")) << output;
}

TEST(LrfSession, ASessionThatDoesNotOpenIsMovedAsideOrItsBackupResumedAndFreshStartsOver) {
  const std::filesystem::path manifest = LrfDatasetIn("lrf_session_aside");
  const std::filesystem::path session_file = DefaultLrfSessionPath(manifest);
  std::ofstream(session_file) << "{\"format\": \"calibench.session.v1\", \"version\": 1, tru";
  LrfController controller;
  OpenAndWait(controller, manifest);
  LrfSnapshot s = controller.GetSnapshot();
  EXPECT_TRUE(Says(s.session_note, "did not open")) << s.session_note;
  EXPECT_TRUE(Says(s.session_note, ".bak")) << s.session_note;
  int kept = 0;
  for (const auto& entry : std::filesystem::directory_iterator(session_file.parent_path()))
    if (entry.path().extension() == ".bak" &&
        test::ReadFileBytes(entry.path()).find("tru") != std::string::npos)
      ++kept;
  EXPECT_EQ(kept, 1);                       // the unreadable file, as it was
  EXPECT_TRUE(IsLrfSession(session_file));  // a new session in its place

  controller.Apply(LrfSetPairStatus{0, PairStatus::kRejected});
  ASSERT_TRUE(controller.Open(manifest, ExistingSession::kStartFresh));
  controller.WaitIdle();
  s = controller.GetSnapshot();
  EXPECT_TRUE(Says(s.session_note, "started over")) << s.session_note;
  EXPECT_EQ(s.pairs[0].status, PairStatus::kAccepted);
  EXPECT_EQ(LoadSession(session_file).pairs[0].status, PairStatus::kPending);

  // Resumed, the file as found becomes the newest backup; when the file later does not open, that
  // backup is resumed instead and the file is kept aside.
  controller.Apply(LrfSetPairStatus{1, PairStatus::kRejected});
  OpenAndWait(controller, manifest);
  ASSERT_TRUE(std::filesystem::exists(SessionBackupPath(session_file, 1)));
  std::ofstream(session_file, std::ios::trunc) << "{";
  OpenAndWait(controller, manifest);
  s = controller.GetSnapshot();
  EXPECT_TRUE(Says(s.session_note, "resumed its newest backup that opens")) << s.session_note;
  EXPECT_EQ(s.pairs[1].status, PairStatus::kRejected);
  EXPECT_EQ(LoadSession(session_file).pairs[1].status, PairStatus::kRejected);
}

TEST(LrfSession, CalibrateRefusesALidarCameraFlagOnAnLrfSessionNamingBoth) {
  const std::filesystem::path manifest = LrfDatasetIn("lrf_session_lidar_camera_flag");
  const std::filesystem::path session_file = DefaultLrfSessionPath(manifest);
  SaveSession(session_file, NewLrfSession(LoadLrfDataset(manifest), LrfMethod::kRefined));
  std::string output;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --session " +
                                 session_file.string() + " --method kim",
                             &output),
            1);  // kUsage: nothing solved
  EXPECT_TRUE(Says(output, session_file.string())) << output;
  EXPECT_TRUE(Says(output, "--method is the LiDAR-camera method's")) << output;
  EXPECT_FALSE(Says(output, "wrote")) << output;
}

}  // namespace
}  // namespace calibench::ui
