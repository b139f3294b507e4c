// Repainting only what changed (ui/widgets/redraw_regions.h) must show exactly what repainting
// everything shows: the same edits and mouse moves are played twice, once with region repaints
// into one persistent framebuffer and once repainting the whole frame, and every picture must be
// identical to the byte. And it must actually save work: a frame in which nothing changed
// repaints no pixel, a rejected pair only the panels that show it.
#include <gtest/gtest.h>
#include <imgui.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "tests/test_support.h"
#include "tests/ui/golden.h"
#include "tests/ui/ui_fixture.h"
#include "ui/gfx/context.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/gl_api.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {
namespace {

constexpr int kWidth = 1280, kHeight = 720;

struct Step {
  std::string what;
  ImageU8 picture;
  int frames = 0;
  long long repainted_pixels = 0;  // over the step's frames
};

// The edits a user makes, each followed by two frames (ImGui settles hover and layout in the
// second); the picture after each.
std::vector<Step> PlayEdits(bool repaint_only_changes, const std::string& session) {
  ImGuiHost host(nullptr);
  host.set_repaint_only_changes(repaint_only_changes);
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir(session) / "s.json");
  controller.WaitIdle();
  controller.Apply(RunSolver{});
  controller.WaitIdle();
  Workbench workbench;
  gfx::Framebuffer target;
  ImVec2 mouse(-100, -100);
  std::vector<Step> steps;
  auto frames = [&](const std::string& what, int count) {
    long long repainted = 0;
    for (int i = 0; i < count; ++i) {
      ImGui::GetIO().MousePos = mouse;
      controller.WaitIdle();
      host.DrawFrame(target, kWidth, kHeight, 1.0 / 60.0, [&] {
        for (const Intent& intent : workbench.Frame(controller.GetSnapshot(), kWidth, kHeight,
                                                    Layout::kWorkbench, 1.0 / 60.0))
          controller.Apply(intent);
      });
      // The first frames lay the workbench out: count from the last of them.
      repainted =
          i + 1 == count || what != "first frames" ? repainted + host.last_repainted_pixels() : 0;
    }
    glFinish();
    steps.push_back({what, target.ReadPixels(), count, repainted});
  };
  auto edit_view = [&](auto change) {
    ViewState view = controller.GetSnapshot().view;
    change(view);
    controller.Apply(SetView{view});
  };
  frames("first frames", 4);
  frames("nothing changed", 1);
  edit_view([](ViewState& v) { v.orbit_yaw_rad += 0.2; });
  frames("3D view turned", 2);
  edit_view([](ViewState& v) { v.point_opacity = 0.6; });
  frames("camera points restyled", 2);
  controller.Apply(SetPairStatus{1, PairStatus::kRejected});
  frames("pair 1 rejected", 2);
  frames("nothing changed after the rejection", 1);
  controller.Apply(SelectPair{2});
  frames("pair 2 selected", 2);
  mouse = ImVec2(kWidth * 0.5f, kHeight * 0.3f);  // over the camera view: a tooltip or hover
  frames("mouse over the camera view", 2);
  mouse = ImVec2(kWidth * 0.2f, kHeight * 0.8f);  // over the measurements list
  frames("mouse over the list", 2);
  mouse = ImVec2(-100, -100);
  frames("mouse gone", 2);
  return steps;
}

TEST(RedrawRegions, RepaintingChangesGivesTheWholeFramesPictures) {
  const auto context = HeadlessOrSkip();
  if (!context) GTEST_SKIP() << "no headless OpenGL (EGL or OSMesa) on this machine";
  const std::vector<Step> regions = PlayEdits(true, "redraw_regions");
  const std::vector<Step> whole = PlayEdits(false, "redraw_whole");
  ASSERT_EQ(regions.size(), whole.size());
  const long long display = static_cast<long long>(kWidth) * kHeight;
  for (size_t i = 0; i < regions.size(); ++i) {
    SCOPED_TRACE(regions[i].what);
    if (i > 0) {
      EXPECT_EQ(whole[i].repainted_pixels, whole[i].frames * display);
    }
    std::printf("%-40s repainted %5.1f %% of the display\n", regions[i].what.c_str(),
                100.0 * regions[i].repainted_pixels / display);
    ASSERT_EQ(regions[i].picture.data.size(), whole[i].picture.data.size());
    size_t differing = 0;
    for (size_t b = 0; b < regions[i].picture.data.size(); ++b)
      differing += regions[i].picture.data[b] != whole[i].picture.data[b];
    EXPECT_EQ(differing, 0u) << "bytes differ from the whole frame's picture";
  }
  // The work saved. Indices follow PlayEdits.
  EXPECT_EQ(regions[0].repainted_pixels, 0) << "the 4th identical first frame repaints nothing";
  EXPECT_EQ(regions[1].repainted_pixels, 0);
  EXPECT_EQ(regions[5].repainted_pixels, 0);
  // A turned 3D view repaints that view (a third of the width, the upper part) and little else.
  EXPECT_GT(regions[2].repainted_pixels, display / 10);
  EXPECT_LT(regions[2].repainted_pixels, display / 3);
  // A rejected pair: the list, the status line and the solver panel; no view.
  EXPECT_GT(regions[4].repainted_pixels, 0);
  EXPECT_LT(regions[4].repainted_pixels, display / 2);
}

}  // namespace
}  // namespace calibench::ui
