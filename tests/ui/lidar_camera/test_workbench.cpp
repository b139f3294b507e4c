// The workbench drawn headless (EGL surfaceless, Mesa llvmpipe): golden screenshots of each view
// and of the whole layout before and after a solve, panels driven frame by frame with synthetic
// input, and a saved-and-reopened session that must render identically.
#include <gtest/gtest.h>
#include <imgui.h>

#include <cmath>
#include <cstdlib>
#include <set>

#include "core/base/image.h"
#include "core/io/image_io.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"
#include "tests/ui/golden.h"
#include "tests/ui/ui_fixture.h"
#include "ui/gfx/context.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {
namespace {

class WorkbenchRender : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = HeadlessOrSkip();
    if (!context_) GTEST_SKIP() << "no headless OpenGL (EGL or OSMesa) on this machine";
    host_ = std::make_unique<ImGuiHost>(nullptr);
  }
  void TearDown() override { host_.reset(); }
  ImageU8 Render(Controller& controller, Layout layout, int width, int height) {
    Workbench workbench;
    return RenderWorkbenchHeadless(controller, workbench, *host_, layout, width, height, 4);
  }
  std::unique_ptr<gfx::GlContext> context_;
  std::unique_ptr<ImGuiHost> host_;
};

TEST_F(WorkbenchRender, GoldenViewsBeforeAndAfterASolve) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("golden_session") / "s.json");
  controller.WaitIdle();
  ExpectMatchesGolden(Render(controller, Layout::kLidarOnly, 480, 300), "lidar_before");
  ExpectMatchesGolden(Render(controller, Layout::kCameraOnly, 480, 300), "camera_before");
  ExpectMatchesGolden(Render(controller, Layout::kSceneOnly, 480, 300), "scene_before");
  ExpectMatchesGolden(Render(controller, Layout::kWorkbench, 1280, 720), "workbench_before");
  controller.Apply(RunSolver{});
  controller.WaitIdle();
  ExpectMatchesGolden(Render(controller, Layout::kCameraOnly, 480, 300), "camera_after");
  ExpectMatchesGolden(Render(controller, Layout::kSceneOnly, 480, 300), "scene_after");
  ExpectMatchesGolden(Render(controller, Layout::kWorkbench, 1280, 720), "workbench_after");
  // `render --view guide`: the camera and 3D views with the ghost board over the meter.
  ExpectMatchesGolden(Render(controller, Layout::kGuide, 1280, 720), "guide_after");
}

// One frame with the given input; returns the intents the panels produced (not yet applied).
std::vector<Intent> FrameWithInput(Controller& controller, Workbench& workbench, ImGuiHost& host,
                                   Layout layout, ImVec2 mouse, bool mouse_down, int key) {
  ImGuiIO& io = ImGui::GetIO();
  io.MousePos = mouse;
  io.MouseDown[0] = mouse_down;
  for (bool& k : io.KeysDown) k = false;
  if (key >= 0) io.KeysDown[key] = true;
  controller.WaitIdle();
  host.NewFrame(1280, 720, 1.0 / 60.0);
  auto intents = workbench.Frame(controller.GetSnapshot(), 1280, 720, layout, 1.0 / 60.0);
  ImGui::Render();
  return intents;
}

TEST_F(WorkbenchRender, PanelsDrivenFrameByFrame) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("panels_session") / "s.json");
  controller.WaitIdle();
  // Where the board is on the LiDAR image, from the seeded fit; then clear the brush.
  const Snapshot start = controller.GetSnapshot();
  const PairView& pair = start.pairs[0];
  const int board_pixel =
      pair.lidar_image->pixel_of_point[pair.lidar->inliers[pair.lidar->inliers.size() / 2]];
  const int columns = pair.lidar_image->columns, rows = pair.lidar_image->rows;
  controller.Apply(ClearBrush{0});
  controller.WaitIdle();
  ASSERT_FALSE(controller.GetSnapshot().pairs[0].lidar);

  Workbench workbench;
  FrameWithInput(controller, workbench, *host_, Layout::kLidarOnly, {-1, -1}, false, -1);
  const auto& rect = workbench.lidar_image_rect();
  const float u = (board_pixel % columns + 0.5f) / columns;
  const ImVec2 aim(
      rect.x + (u - rect.u0) / (rect.u1 - rect.u0) * rect.w,
      rect.y + ((board_pixel / columns + 0.5f) / rows - rect.v0) / (rect.v1 - rect.v0) * rect.h);
  ASSERT_GT(aim.x, rect.x);
  ASSERT_LT(aim.x, rect.x + rect.w);
  // A brush stroke: the LiDAR view returns it, the controller fits the plane.
  const auto stroke =
      FrameWithInput(controller, workbench, *host_, Layout::kLidarOnly, aim, true, -1);
  ASSERT_EQ(stroke.size(), 1u);
  const auto* brush = std::get_if<BrushStroke>(&stroke[0]);
  ASSERT_TRUE(brush);
  EXPECT_EQ(brush->row * columns + brush->column, board_pixel);
  EXPECT_FALSE(brush->erase);
  for (const Intent& i : stroke) controller.Apply(i);
  controller.WaitIdle();
  ASSERT_TRUE(controller.GetSnapshot().pairs[0].lidar)
      << controller.GetSnapshot().pairs[0].lidar_failure;
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kAccepted);

  // R rejects, A accepts the selected pair.
  FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, -1);
  auto intents =
      FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, 'R');
  ASSERT_EQ(intents.size(), 1u);
  controller.Apply(intents[0]);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kRejected);
  FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, -1);
  intents = FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, 'A');
  ASSERT_EQ(intents.size(), 1u);
  controller.Apply(intents[0]);
  EXPECT_EQ(controller.GetSnapshot().pairs[0].status, PairStatus::kAccepted);

  // F5 runs the solver, which converges.
  FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, -1);
  intents = FrameWithInput(controller, workbench, *host_, Layout::kWorkbench, {-1, -1}, false, 294);
  ASSERT_EQ(intents.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<RunSolver>(intents[0]));
  controller.Apply(intents[0]);
  controller.WaitIdle();
  const Snapshot solved = controller.GetSnapshot();
  ASSERT_TRUE(solved.solver.result);
  EXPECT_TRUE(solved.solver.result->converged);
}

// The board painted in the 3D view: the stroke selects the board's returns (not the wall behind),
// the plane refitted to them is the seeded one, and the view shows it (golden).
TEST_F(WorkbenchRender, TheBoardPaintedInTheThreeDViewGivesItsPlane) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("scene_brush_session") / "s.json");
  controller.WaitIdle();
  const PairView seeded = controller.GetSnapshot().pairs[0];
  ASSERT_TRUE(seeded.lidar);
  Vec3 board_centre = Vec3::Zero();
  for (int i : seeded.lidar->inliers) board_centre += seeded.cloud->points[i].cast<double>();
  board_centre /= double(seeded.lidar->inliers.size());
  controller.Apply(ClearBrush{0});
  // Look at the board from 2 m: the orbit target on its centre.
  ViewState view = controller.GetSnapshot().view;
  for (int a = 0; a < 3; ++a) view.orbit_target[a] = board_centre[a];
  view.orbit_distance_m = 2.0;
  view.orbit_yaw_rad = std::atan2(board_centre.y(), board_centre.x()) + M_PI;
  controller.Apply(SetView{view});
  controller.WaitIdle();
  ASSERT_FALSE(controller.GetSnapshot().pairs[0].lidar);

  Workbench workbench;
  workbench.set_scene_brush(true);
  FrameWithInput(controller, workbench, *host_, Layout::kSceneOnly, {-1, -1}, false, -1);
  const auto& rect = workbench.scene_image_rect();
  const ImVec2 aim(rect.x + rect.w / 2, rect.y + rect.h / 2);  // the target: the board centre
  const auto stroke =
      FrameWithInput(controller, workbench, *host_, Layout::kSceneOnly, aim, true, -1);
  const PaintPoints* paint = nullptr;
  for (const Intent& i : stroke)
    if (const auto* p = std::get_if<PaintPoints>(&i)) paint = p;
  ASSERT_TRUE(paint) << "the stroke painted nothing";
  EXPECT_FALSE(paint->erase);
  // Every painted pixel is a board return of the seeded fit.
  std::set<int> board_pixels;
  for (int i : seeded.lidar->inliers) board_pixels.insert(seeded.lidar_image->pixel_of_point[i]);
  for (int pixel : paint->pixels) EXPECT_TRUE(board_pixels.count(pixel)) << pixel;
  controller.Apply(*paint);
  controller.WaitIdle();
  const PairView painted = controller.GetSnapshot().pairs[0];
  ASSERT_TRUE(painted.lidar) << painted.lidar_failure;
  EXPECT_EQ(painted.board_origin.source, BoardSource::kBrush);
  EXPECT_GT(std::abs(painted.lidar->plane.normal.dot(seeded.lidar->plane.normal)),
            std::cos(1.0 * M_PI / 180));
  EXPECT_NEAR(painted.lidar->plane.distance, seeded.lidar->plane.distance, 0.01);
  ExpectMatchesGolden(Render(controller, Layout::kSceneOnly, 480, 300), "scene_brushed");
}

// The same on the real VLP-16 (16 rings: the 3D view is where the board is easiest to pick): a
// drag across the board paints only its returns and gives the seeded plane. The frame is saved
// for a look (test_tmp/real_3d_brush/workbench.png).
TEST_F(WorkbenchRender, RealVlp16BoardPaintedInTheThreeDView) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto dir = test::TempDir("real_3d_brush");
  Controller controller;
  controller.OpenDataset(test::WriteAcfrManifest(shared / "datasets/acfr-vlp16-chessboard", dir),
                         dir / "s.json");
  controller.WaitIdle();
  int index = -1;
  for (size_t i = 0; i < controller.GetSnapshot().pairs.size(); ++i)
    if (controller.GetSnapshot().pairs[i].id == "pose16") index = static_cast<int>(i);
  ASSERT_GE(index, 0);
  const PairView seeded = controller.GetSnapshot().pairs[index];
  ASSERT_TRUE(seeded.lidar);
  Vec3 centre = Vec3::Zero();
  for (int i : seeded.lidar->inliers) centre += seeded.cloud->points[i].cast<double>();
  centre /= double(seeded.lidar->inliers.size());
  controller.Apply(SelectPair{index});
  controller.Apply(ClearBrush{index});
  ViewState view = controller.GetSnapshot().view;
  for (int a = 0; a < 3; ++a) view.orbit_target[a] = centre[a];
  view.orbit_distance_m = 3.0;
  view.orbit_yaw_rad = std::atan2(centre.y(), centre.x());  // from behind the LiDAR
  view.orbit_pitch_rad = 0.3;
  controller.Apply(SetView{view});
  controller.WaitIdle();

  Workbench workbench;
  workbench.set_scene_brush(true);
  FrameWithInput(controller, workbench, *host_, Layout::kSceneOnly, {-1, -1}, false, -1);
  const auto& rect = workbench.scene_image_rect();
  std::set<int> board_pixels;
  for (int i : seeded.lidar->inliers) board_pixels.insert(seeded.lidar_image->pixel_of_point[i]);
  int painted = 0, off_board = 0;
  for (int dx = -30; dx <= 30; dx += 10) {  // one drag across the board's middle
    const ImVec2 aim(rect.x + rect.w / 2 + dx, rect.y + rect.h / 2);
    for (const Intent& intent :
         FrameWithInput(controller, workbench, *host_, Layout::kSceneOnly, aim, true, -1)) {
      if (const auto* paint = std::get_if<PaintPoints>(&intent)) {
        painted += static_cast<int>(paint->pixels.size());
        for (int pixel : paint->pixels) off_board += !board_pixels.count(pixel);
      }
      controller.Apply(intent);
    }
  }
  for (const Intent& intent :
       FrameWithInput(controller, workbench, *host_, Layout::kSceneOnly, {-1, -1}, false, -1))
    controller.Apply(intent);  // the release ends the stroke
  controller.WaitIdle();
  EXPECT_GT(painted, 50);
  EXPECT_EQ(off_board, 0);
  const PairView brushed = controller.GetSnapshot().pairs[index];
  ASSERT_TRUE(brushed.lidar) << brushed.lidar_failure;
  EXPECT_EQ(brushed.board_origin.source, BoardSource::kBrush);
  EXPECT_GT(std::abs(brushed.lidar->plane.normal.dot(seeded.lidar->plane.normal)),
            std::cos(1.0 * M_PI / 180));
  EXPECT_NEAR(brushed.lidar->plane.distance, seeded.lidar->plane.distance, 0.01);
  SaveImage(dir / "workbench.png", RenderWorkbenchHeadless(controller, workbench, *host_,
                                                           Layout::kWorkbench, 1600, 900, 4));
}

// The LiDAR colour selector draws the channel it shows, in one workbench across frames (it once
// drew the previously chosen one).
TEST_F(WorkbenchRender, TheLidarChannelShownIsTheOneChosen) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("channel_session") / "s.json");
  controller.WaitIdle();
  Workbench workbench;  // one instance: its redraw check is what is tested
  auto render = [&] {
    return RenderWorkbenchHeadless(controller, workbench, *host_, Layout::kLidarOnly, 480, 300, 2);
  };
  auto fresh = [&] {  // a workbench that never saw another channel
    Workbench other;
    return RenderWorkbenchHeadless(controller, other, *host_, Layout::kLidarOnly, 480, 300, 2);
  };
  auto choose = [&](LidarChannel channel) {
    ViewState view = controller.GetSnapshot().view;
    view.lidar_channel = channel;
    controller.Apply(SetView{view});
  };
  const ImageU8 intensity = render();
  for (LidarChannel channel :
       {LidarChannel::kRange, LidarChannel::kRing, LidarChannel::kIntensity}) {
    choose(channel);
    const ImageU8 shown = render();
    EXPECT_EQ(shown.data, fresh().data) << LidarChannelName(channel);
    if (channel != LidarChannel::kIntensity) {
      EXPECT_NE(shown.data, intensity.data);
    }
  }
}

TEST_F(WorkbenchRender, ASavedAndReopenedSessionRendersIdentically) {
  const auto path = test::TempDir("reopen_session") / "work.session.json";
  ImageU8 before;
  {
    Controller controller;
    controller.OpenDataset(test::UiDataset(), path);
    controller.WaitIdle();
    controller.Apply(SelectPair{2});
    controller.Apply(SetPairStatus{1, PairStatus::kRejected});
    controller.Apply(RunSolver{});
    controller.WaitIdle();
    before = Render(controller, Layout::kWorkbench, 1280, 720);
  }
  Controller reopened;
  reopened.OpenSession(path);
  reopened.WaitIdle();
  const ImageU8 after = Render(reopened, Layout::kWorkbench, 1280, 720);
  ASSERT_EQ(before.data.size(), after.data.size());
  // Everything but the status line (the last message, "solved ..." vs "loaded ...") must match.
  const size_t status_bytes = static_cast<size_t>(40) * before.width * 3;
  size_t differing = 0;
  for (size_t i = 0; i + status_bytes < before.data.size(); ++i)
    differing += before.data[i] != after.data[i];
  if (differing) {
    const auto dir = test::TempDir("reopen_failure");
    SaveImage(dir / "before.png", before);
    SaveImage(dir / "after.png", after);
  }
  EXPECT_EQ(differing, 0u) << "see before.png / after.png in test_tmp/reopen_failure";
}

}  // namespace
}  // namespace calibench::ui

namespace calibench::ui {
namespace {

// Issue "Camera intrinsics", item 5: the workbench estimates the intrinsics from the loaded pairs
// (the step `calibench intrinsics` runs), shows the coverage map and the per-image error, and
// writes them beside the dataset on request.
TEST_F(WorkbenchRender, TheIntrinsicsWindowEstimatesShowsAndSaves) {
  const auto dir = test::TempDir("intrinsics_window");
  std::filesystem::copy(test::UiDataset().parent_path(), dir / "set",
                        std::filesystem::copy_options::recursive);
  Controller controller;
  controller.OpenDataset(dir / "set" / test::UiDataset().filename(), dir / "s.json");
  const Snapshot loaded = Loaded(controller);
  int with_corners = 0;
  for (const PairView& pair : loaded.pairs) with_corners += pair.detection.has_value();
  ASSERT_GE(with_corners, 3);
  controller.Apply(EstimateIntrinsics{loaded.dataset->camera.type});
  const Snapshot estimated = Loaded(controller);
  ASSERT_TRUE(estimated.intrinsics) << estimated.intrinsics_failure;
  const IntrinsicsResult& r = *estimated.intrinsics;
  const CameraModel& truth = loaded.dataset->camera;  // the simulator's camera
  EXPECT_NEAR(r.camera.fx, truth.fx, 0.03 * truth.fx);
  EXPECT_NEAR(r.camera.cx, truth.cx, 0.03 * truth.cx);
  EXPECT_EQ(static_cast<int>(r.images.size()), with_corners);
  EXPECT_NE(estimated.status_line.find("intrinsics: fx"), std::string::npos)
      << estimated.status_line;
  // Four pairs do not cover the image: the verdict says so, and the map shows empty cells.
  EXPECT_FALSE(r.good);
  EXPECT_LT(r.coverage.border_covered, 1.0);

  // The window drawn over the workbench: its empty cells in the map's red.
  Workbench workbench;
  workbench.set_intrinsics_open(true);
  const ImageU8 shot =
      RenderWorkbenchHeadless(controller, workbench, *host_, Layout::kWorkbench, 1400, 900, 4);
  SaveImage(dir / "intrinsics_window.png", shot);
  int red = 0;
  for (int i = 0; i < shot.width * shot.height; ++i) {
    const std::uint8_t* p = &shot.data[static_cast<size_t>(i) * shot.channels];
    red += p[1] == 40 && ((p[2] == 150 && p[0] == 35) || (p[0] == 150 && p[2] == 35));
  }
  EXPECT_GT(red, 1000) << "no empty coverage cell drawn; see " << (dir / "intrinsics_window.png");

  // Saved beside the dataset, with its covariance; the dataset's camera stays as it was.
  controller.Apply(SaveIntrinsics{"camera.estimated.yaml", CameraFileFormat::kOpenCv});
  const Snapshot saved = Loaded(controller);
  ASSERT_EQ(saved.intrinsics_saved, dir / "set/camera.estimated.yaml") << saved.status_line;
  const CameraModel back = LoadCameraFile(saved.intrinsics_saved);
  EXPECT_EQ(back.fx, r.camera.fx);
  EXPECT_EQ(back.covariance, r.camera.covariance);
  EXPECT_EQ(saved.dataset->camera.fx, truth.fx);
}

}  // namespace
}  // namespace calibench::ui
