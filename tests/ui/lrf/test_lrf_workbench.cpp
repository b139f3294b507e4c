// The 2D LRF workbench: the controller against a small simulated three-face dataset (extraction,
// accept/reject, solving against ground truth, export, a bad manifest), the panels driven frame
// by frame with synthetic keys, and golden screenshots of each layout drawn headless (EGL
// surfaceless, Mesa llvmpipe).
#include <gtest/gtest.h>
#include <imgui.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/base/image.h"
#include "core/geometry/geometry.h"
#include "core/results/result_file.h"
#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"
#include "tests/ui/golden.h"
#include "ui/gfx/context.h"
#include "ui/lrf/controller.h"
#include "ui/lrf/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {
namespace {

constexpr int kObservations = 6;

// Six "paper" observations (R2000-like scan, ZED-like depth at half resolution), seed 5: the
// goldens depend on it. Made once per test process, in a folder of its own (ctest runs tests in
// parallel processes).
std::filesystem::path LrfUiDataset() {
  static const std::filesystem::path manifest = [] {
    LrfSimOptions options = *LrfSimPreset("paper");
    options.observations = kObservations;
    options.seed = 2;  // all six observations extract (about 1 in 10 fails at 3 m in general)
    return WriteLrfSimDataset(options, test::TempDir("lrf_ui_dataset_" + std::to_string(getpid())));
  }();
  return manifest;
}

// Opens the dataset and waits for every pair's features. In memory: the tests of one process share
// the dataset, and a session one of them left beside it would carry into the next (the session's
// own tests are in test_lrf_session.cpp).
void OpenAndWait(LrfController& controller) {
  ASSERT_TRUE(controller.Open(LrfUiDataset(), ExistingSession::kInMemory))
      << controller.GetSnapshot().status_line;
  controller.WaitIdle();
}

double RotationErrorDeg(const Pose& a, const Pose& b) {
  return RotationAngle(a.linear(), b.linear()) * 180.0 / M_PI;
}

TEST(LrfController, ExtractsEveryPairAndSolvesNearTheTruth) {
  LrfController controller;
  OpenAndWait(controller);
  LrfSnapshot s = controller.GetSnapshot();
  ASSERT_TRUE(s.dataset);
  ASSERT_EQ(s.pairs.size(), static_cast<size_t>(kObservations));
  EXPECT_EQ(s.extracted_done, kObservations);
  EXPECT_FALSE(s.busy);
  EXPECT_FALSE(s.status_is_error) << s.status_line;
  for (const LrfPairView& pair : s.pairs) {
    EXPECT_TRUE(pair.extracted) << pair.id;
    ASSERT_TRUE(pair.features) << pair.id;
    EXPECT_EQ(pair.status, PairStatus::kAccepted) << pair.id << ": " << pair.reason;
    ASSERT_TRUE(pair.features->three_face) << pair.id;
    EXPECT_EQ(pair.features->three_face->depth.face_of_pixel.size(),
              pair.features->depth->depth_m.size())
        << pair.id;
  }
  ASSERT_TRUE(s.dataset->cam_from_lrf_ground_truth);
  const Pose truth = *s.dataset->cam_from_lrf_ground_truth;

  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  s = controller.GetSnapshot();
  ASSERT_TRUE(s.solver.solution) << s.solver.failure;
  const LrfSolution& refined = *s.solver.solution;
  EXPECT_EQ(refined.method, LrfMethod::kRefined);
  EXPECT_FALSE(s.solver.running);
  EXPECT_EQ(s.solver.solved_pair_ids.size(), static_cast<size_t>(kObservations));
  EXPECT_LT(RotationErrorDeg(refined.cam_from_lrf, truth), 1.0);
  EXPECT_LT((refined.cam_from_lrf.translation() - truth.translation()).norm(), 0.02);
  // The refinement's iterations are there to replay, the seed first, ending at the solution.
  ASSERT_GE(s.solver.iterations.size(), 2u);
  EXPECT_TRUE(test::MatrixNear(s.solver.iterations.back().cam_from_lidar.matrix(),
                               refined.cam_from_lrf.matrix(), 1e-12));
  EXPECT_GT(s.solver.std_translation_mm.minCoeff(), 0.0);
  for (const LrfPairView& pair : s.pairs) {
    ASSERT_TRUE(pair.point_to_line_m) << pair.id;
    EXPECT_LT(*pair.point_to_line_m, 0.05) << pair.id;
    ASSERT_TRUE(pair.point_to_plane_rms_m) << pair.id;
    EXPECT_LT(*pair.point_to_plane_rms_m, 0.05) << pair.id;
  }

  // The paper's closed form: no iterations, a looser bound.
  controller.Apply(LrfSetMethod{LrfMethod::kPaperLinear});
  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  s = controller.GetSnapshot();
  ASSERT_TRUE(s.solver.solution) << s.solver.failure;
  EXPECT_EQ(s.solver.solution->method, LrfMethod::kPaperLinear);
  EXPECT_TRUE(s.solver.iterations.empty());
  EXPECT_LT(RotationErrorDeg(s.solver.solution->cam_from_lrf, truth), 2.0);
  EXPECT_LT((s.solver.solution->cam_from_lrf.translation() - truth.translation()).norm(), 0.03);

  controller.Apply(LrfResetSolver{});
  s = controller.GetSnapshot();
  EXPECT_FALSE(s.solver.solution);
  EXPECT_FALSE(s.pairs[0].point_to_line_m);
}

TEST(LrfController, RejectedPairsStayOutOfTheSolve) {
  LrfController controller;
  OpenAndWait(controller);
  const std::string rejected_id = controller.GetSnapshot().pairs[1].id;
  controller.Apply(LrfSetPairStatus{1, PairStatus::kRejected});
  LrfSnapshot s = controller.GetSnapshot();
  EXPECT_EQ(s.pairs[1].status, PairStatus::kRejected);
  EXPECT_EQ(s.pairs[1].reason, "rejected by the user");
  EXPECT_NE(s.status_line.find(rejected_id), std::string::npos) << s.status_line;
  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  s = controller.GetSnapshot();
  ASSERT_TRUE(s.solver.solution) << s.solver.failure;
  EXPECT_EQ(s.solver.solved_pair_ids.size(), static_cast<size_t>(kObservations - 1));
  for (const std::string& id : s.solver.solved_pair_ids) EXPECT_NE(id, rejected_id);
  // Accepting it again works (it has features); selecting follows the index.
  controller.Apply(LrfSetPairStatus{1, PairStatus::kAccepted});
  controller.Apply(LrfSelectPair{3});
  s = controller.GetSnapshot();
  EXPECT_EQ(s.pairs[1].status, PairStatus::kAccepted);
  EXPECT_TRUE(s.pairs[1].reason.empty());
  EXPECT_EQ(s.selected, 3);
  controller.Apply(LrfSelectPair{kObservations});  // out of range: ignored
  EXPECT_EQ(controller.GetSnapshot().selected, 3);
}

// One job (core/session/lrf_calibration_job.h): the workbench and `calibench lrf-calibrate` run the
// same extraction and solve, so a rejection made in the workbench and the same pair left out on the
// command line give the same transform, bit for bit.
TEST(LrfController, TheWorkbenchAndLrfCalibrateRunOneJob) {
  LrfController controller;
  OpenAndWait(controller);
  const LrfSnapshot opened = controller.GetSnapshot();
  controller.Apply(LrfSetPairStatus{2, PairStatus::kRejected});
  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  const LrfSnapshot gui = controller.GetSnapshot();
  ASSERT_TRUE(gui.solver.solution) << gui.solver.failure;

  LrfPipelineOptions options;
  for (const LrfPairView& pair : opened.pairs)
    if (pair.id != opened.pairs[2].id) options.pair_ids.push_back(pair.id);
  const LrfCalibrationOutcome cli = CalibrateLrfDataset(*opened.dataset, options);
  ASSERT_TRUE(cli.solution) << cli.failure;
  EXPECT_EQ(gui.solver.solution->cam_from_lrf.matrix(), cli.solution->cam_from_lrf.matrix());
  EXPECT_EQ(gui.solver.solution->covariance, cli.solution->covariance);

  // The command itself, its result file read back.
  std::string pairs;
  for (const std::string& id : options.pair_ids) pairs += (pairs.empty() ? "" : ",") + id;
  const auto out = test::TempDir("lrf_one_job") / "result.json";
  std::string output;
  ASSERT_EQ(
      test::RunCommand(test::CalibenchExe() + " lrf-calibrate --dataset " +
                           LrfUiDataset().string() + " --pairs " + pairs + " --out " + out.string(),
                       &output),
      0)
      << output;
  EXPECT_TRUE(test::MatrixNear(LoadResult(out).cam_from_source.matrix(),
                               gui.solver.solution->cam_from_lrf.matrix(), 0.0));
}

TEST(LrfController, ABadManifestShowsAnErrorAndKeepsTheOpenDataset) {
  LrfController controller;
  const auto missing = test::TempDir("lrf_bad_manifest") / "missing.json";
  EXPECT_FALSE(controller.Open(missing));
  LrfSnapshot s = controller.GetSnapshot();
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find("missing.json"), std::string::npos) << s.status_line;
  EXPECT_FALSE(s.dataset);

  OpenAndWait(controller);
  const auto garbage = test::TempDir("lrf_garbage_manifest") / "manifest.json";
  std::ofstream(garbage) << "{\"format\": \"calibench.lrf-dataset.v1\", \"pairs\": 3}";
  EXPECT_FALSE(controller.Open(garbage));
  s = controller.GetSnapshot();
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find("manifest.json"), std::string::npos) << s.status_line;
  ASSERT_TRUE(s.dataset);
  EXPECT_EQ(s.manifest, LrfUiDataset());
  EXPECT_EQ(s.pairs.size(), static_cast<size_t>(kObservations));
  EXPECT_EQ(s.pairs[0].status, PairStatus::kAccepted);
}

TEST(LrfController, ExportsTheSolvedResult) {
  LrfController controller;
  OpenAndWait(controller);
  const auto path = test::TempDir("lrf_export") / "result.json";
  controller.Apply(LrfExportResult{path});
  EXPECT_TRUE(controller.GetSnapshot().status_is_error);
  EXPECT_FALSE(std::filesystem::exists(path));
  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  controller.Apply(LrfExportResult{path});
  const LrfSnapshot s = controller.GetSnapshot();
  EXPECT_FALSE(s.status_is_error) << s.status_line;
  ASSERT_TRUE(std::filesystem::exists(path));
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  EXPECT_NE(text.str().find("cam_from_lrf"), std::string::npos);
  EXPECT_NE(text.str().find("calibench.result.v1"), std::string::npos);
  // A relative name (the solver panel's default, lrf_result.json) goes beside the manifest, not
  // into the working directory.
  const auto beside = LrfUiDataset().parent_path() / "relative_result.json";
  std::filesystem::remove(beside);
  controller.Apply(LrfExportResult{"relative_result.json"});
  EXPECT_FALSE(controller.GetSnapshot().status_is_error) << controller.GetSnapshot().status_line;
  EXPECT_TRUE(std::filesystem::exists(beside));
  EXPECT_FALSE(std::filesystem::exists("relative_result.json"));
  EXPECT_EQ(test::ReadFileBytes(beside), test::ReadFileBytes(path));
}

class LrfWorkbenchRender : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = HeadlessOrSkip();
    if (!context_) GTEST_SKIP() << "no headless OpenGL (EGL or OSMesa) on this machine";
    host_ = std::make_unique<ImGuiHost>(nullptr);
  }
  void TearDown() override { host_.reset(); }
  ImageU8 Render(LrfController& controller, LrfLayout layout, int width, int height) {
    LrfWorkbench workbench;
    return RenderWorkbenchHeadless(controller, workbench, *host_, layout, width, height, 4);
  }
  std::unique_ptr<gfx::GlContext> context_;
  std::unique_ptr<ImGuiHost> host_;
};

TEST_F(LrfWorkbenchRender, GoldenLayoutsAfterASolve) {
  LrfController controller;
  OpenAndWait(controller);
  controller.Apply(LrfRunSolver{});
  controller.WaitIdle();
  ASSERT_TRUE(controller.GetSnapshot().solver.solution);
  for (const auto& [name, width, height] : {std::tuple<std::string, int, int>{"scan", 480, 360},
                                            {"depth", 480, 300},
                                            {"3d", 480, 300},
                                            {"workbench", 1280, 720}}) {
    LrfLayout layout;
    ASSERT_TRUE(ParseLrfLayout(name, &layout)) << name;
    ExpectMatchesGolden(Render(controller, layout, width, height), "lrf_" + name);
  }
  LrfLayout layout;
  EXPECT_FALSE(ParseLrfLayout("lidar", &layout));
}

// One frame with a key held; returns the intents the panels produced (not yet applied).
std::vector<LrfIntent> FrameWithKey(LrfController& controller, LrfWorkbench& workbench,
                                    ImGuiHost& host, int key, bool ctrl = false) {
  ImGuiIO& io = ImGui::GetIO();
  io.MousePos = {-1, -1};
  for (bool& k : io.KeysDown) k = false;
  if (key >= 0) io.KeysDown[key] = true;
  io.KeyCtrl = ctrl;
  controller.WaitIdle();
  host.NewFrame(1280, 720, 1.0 / 60.0);
  auto intents =
      workbench.Frame(controller.GetSnapshot(), 1280, 720, LrfLayout::kWorkbench, 1.0 / 60.0);
  ImGui::Render();
  return intents;
}

TEST_F(LrfWorkbenchRender, KeysRejectAcceptUndoRedoSelectAndSolve) {
  LrfController controller;
  OpenAndWait(controller);
  LrfWorkbench workbench;
  auto press = [&](int key, bool ctrl = false) {
    FrameWithKey(controller, workbench, *host_, -1);  // release first: presses are edges
    auto intents = FrameWithKey(controller, workbench, *host_, key, ctrl);
    for (const LrfIntent& intent : intents) controller.Apply(intent);
    return intents;
  };
  ASSERT_EQ(press('R').size(), 1u);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kRejected);
  ASSERT_EQ(press('A').size(), 1u);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kAccepted);
  // Ctrl+Z takes the acceptance back, Ctrl+Y makes it again.
  ASSERT_EQ(press('Z', true).size(), 1u);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kRejected);
  EXPECT_TRUE(controller.GetSnapshot().can_redo);
  ASSERT_EQ(press('Y', true).size(), 1u);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kAccepted);
  ASSERT_EQ(press(ImGui::GetIO().KeyMap[ImGuiKey_DownArrow]).size(), 1u);
  EXPECT_EQ(controller.GetSnapshot().selected, 1);
  const auto solve = press(294);  // F5
  ASSERT_EQ(solve.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<LrfRunSolver>(solve[0]));
  controller.WaitIdle();
  EXPECT_TRUE(controller.GetSnapshot().solver.solution);
}

}  // namespace
}  // namespace calibench::ui
