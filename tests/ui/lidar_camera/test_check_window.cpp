// The workbench's targetless check (ui/lidar_camera/check_task.h) without a window: a
// drive through a simulated textured room opened as a folder without a board; a calibration
// turned by 1° checked from its file is judged miscalibrated, the estimate adopted comes back to
// the truth with its provenance, exports as a targetless result, survives the session's reopening
// and is one undo step; the workbench's own (adopted) calibration checked again is consistent.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/evaluation/check_sweep.h"
#include "core/targetless/edge_alignment.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

namespace fs = std::filesystem;

// The rotation and translation from `truth` to `estimate` on camera axes (degrees, mm).
std::pair<double, double> ErrorOf(const Pose& estimate, const Pose& truth) {
  const Vec6 delta = DeltaOnCameraAxes(truth, estimate);
  return {delta.tail<3>().norm() * kRadToDeg, 1e3 * delta.head<3>().norm()};
}

TEST(CheckWindow, ATurnedCalibrationIsCaughtItsEstimateAdoptedExportedReopenedAndUndone) {
  const fs::path dir = test::TempDir("check_window");
  CheckSweepOptions options;
  options.lidar = "os0-128";
  options.moving = true;
  options.frames = 12;
  const SimulatedCheckScene scene = SimulateCheckScene(options, 3);
  WriteCheckScene(scene, dir / "drive");
  Vec6 turn = Vec6::Zero();
  turn.tail<3>() = Vec3(0.6, -0.5, 0.62).normalized() * kDegToRad;
  test::WriteBareResult(dir / "turned.json", PerturbOnCameraAxes(scene.cam_from_lidar, turn));
  const fs::path session = dir / "drive.session.json";

  Controller controller;
  // A drive has no board: the folder has no target.json, and the workbench opens it saying so.
  controller.OpenDataset(dir / "drive", session);
  Snapshot s = Loaded(controller);
  ASSERT_EQ(s.pairs.size(), 12u);
  EXPECT_NE(s.status_line.find("target.json"), std::string::npos) << s.status_line;
  for (const PairView& pair : s.pairs) {  // no board searched for, and each pair says why
    EXPECT_EQ(pair.status, PairStatus::kFailed);
    EXPECT_NE(pair.reason.find("no target.json"), std::string::npos) << pair.reason;
  }
  // Nothing solved: the workbench's own calibration cannot be checked, and it says why.
  controller.Apply(RunCheck{});
  s = Loaded(controller);
  EXPECT_FALSE(s.check.report);
  EXPECT_NE(s.check.failure.find("solve first"), std::string::npos) << s.check.failure;
  // A file that is no result: refused, naming it.
  controller.Apply(RunCheck{dir / "missing.json"});
  s = Loaded(controller);
  EXPECT_NE(s.check.failure.find("missing.json"), std::string::npos) << s.check.failure;
  EXPECT_TRUE(s.status_is_error);

  controller.Apply(RunCheck{dir / "turned.json"});
  s = Loaded(controller);
  ASSERT_TRUE(s.check.report) << s.check.failure;
  // Held here: the snapshots below replace `s`, and with it their pointer to this report.
  const std::shared_ptr<const CheckReport> checked = s.check.report;
  const CheckReport& report = *checked;
  EXPECT_EQ(report.verdict, CheckVerdict::kMiscalibrated) << report.why;
  ASSERT_TRUE(report.has_estimate);
  EXPECT_EQ(report.frames_given, 12);
  ASSERT_TRUE(s.check.lidar_edges);
  EXPECT_EQ(s.check.lidar_edges->size(), 12u);
  EXPECT_FALSE(s.check.lidar_edges->begin()->second.empty());
  EXPECT_NE(s.status_line.find("miscalibrated"), std::string::npos) << s.status_line;

  controller.Apply(AdoptCheckEstimate{});
  s = Loaded(controller);
  ASSERT_TRUE(s.solver.result);
  EXPECT_TRUE(s.solver.result->cam_from_lidar.isApprox(report.estimate));
  const auto [deg, mm] = ErrorOf(s.solver.result->cam_from_lidar, scene.cam_from_lidar);
  std::printf("adopted estimate: %.3f deg / %.1f mm from the truth\n", deg, mm);
  EXPECT_LT(deg, 0.3);
  EXPECT_LT(mm, 30.0);
  EXPECT_NE(s.solver.targetless_provenance.find("turned.json"), std::string::npos)
      << s.solver.targetless_provenance;
  EXPECT_TRUE(s.can_undo);

  // Exported: a targetless result, not a board solve.
  controller.Apply(ExportResult{dir / "adopted.result.json"});
  controller.WaitIdle();
  const nlohmann::json exported =
      nlohmann::json::parse(test::ReadFileBytes(dir / "adopted.result.json"));
  EXPECT_EQ(exported["method"], "targetless");
  EXPECT_EQ(exported["provenance"]["kind"], "targetless");
  EXPECT_EQ(exported["provenance"]["text"], s.solver.targetless_provenance);

  // The adopted calibration checked in turn: the scene agrees with it.
  controller.Apply(RunCheck{});
  s = Loaded(controller);
  ASSERT_TRUE(s.check.report) << s.check.failure;
  EXPECT_EQ(s.check.report->verdict, CheckVerdict::kConsistent) << s.check.report->why;
  EXPECT_NE(s.check.checked.find("adopted"), std::string::npos) << s.check.checked;

  // One undo step: before it there was no calibration; redo brings the estimate back.
  controller.Apply(Undo{});
  s = Loaded(controller);
  EXPECT_FALSE(s.solver.result);
  EXPECT_TRUE(s.solver.targetless_provenance.empty());
  controller.Apply(Redo{});
  s = Loaded(controller);
  ASSERT_TRUE(s.solver.result);
  EXPECT_TRUE(s.solver.result->cam_from_lidar.isApprox(report.estimate));
  const std::string provenance = s.solver.targetless_provenance;
  EXPECT_FALSE(provenance.empty());

  // The session keeps it: reopened, the calibration is the adopted one and says so.
  controller.WaitIdle();
  Controller reopened;
  reopened.OpenSession(session, false);
  s = Loaded(reopened);
  ASSERT_TRUE(s.solver.result);
  EXPECT_TRUE(s.solver.result->cam_from_lidar.isApprox(report.estimate, 1e-12));
  EXPECT_EQ(s.solver.targetless_provenance, provenance);
}

}  // namespace
}  // namespace calibench::ui
