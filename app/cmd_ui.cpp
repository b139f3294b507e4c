// `calibench gui` (the workbench window) and `calibench render` (the same views, headless).

// clang-format off
// gl_api.h first: it declares GL for everything below (and sets GLFW_INCLUDE_NONE).
#include "ui/gfx/gl_api.h"
#include <GLFW/glfw3.h>
// clang-format on

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>

#include "app/commands.h"
#include "core/base/image.h"
#include "core/io/image_io.h"
#include "ui/gfx/context.h"
#include "ui/gfx/framebuffer.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lrf/controller.h"
#include "ui/lrf/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::app {
namespace {

bool ParseSize(const std::string& text, int* width, int* height) {
  return std::sscanf(text.c_str(), "%dx%d", width, height) == 2 && *width >= 64 && *height >= 64 &&
         *width <= 8192 && *height <= 8192;
}

// Opens the dataset or session the flags name; false (message printed) when neither is given.
bool OpenInput(ui::Controller& controller, const std::string& dataset, const std::string& session,
               const char* command) {
  if (!session.empty()) {
    controller.OpenSession(session);
  } else if (!dataset.empty()) {
    controller.OpenDataset(dataset);
  } else {
    std::fprintf(stderr, "calibench %s: give --dataset or --session\n", command);
    return false;
  }
  return true;
}

// Opens the window or prints why not.
std::unique_ptr<gfx::WindowContext> OpenWindow(int width, int height, const char* title) {
  std::string why;
  auto context = gfx::WindowContext::Create(width, height, title, &why);
  if (!context)
    std::fprintf(stderr,
                 "calibench gui: cannot open a window: %s\n"
                 "(no display? `calibench render` draws the same views to PNG)\n",
                 why.c_str());
  return context;
}

// The window's frame loop, shared by both workbenches: ui_frame(width, height, dt) issues the
// ImGui calls of one frame and applies their intents. The frame is drawn offscreen, then blitted
// (so that --screenshot reads exactly what is shown).
void RunWindowLoop(gfx::WindowContext& context, ui::ImGuiHost& host,
                   const std::function<void(int, int, double)>& ui_frame,
                   const std::string& screenshot, int quit_after_frames) {
  gfx::Framebuffer frame_target;
  auto last = std::chrono::steady_clock::now();
  for (int frame = 0; !glfwWindowShouldClose(context.window()); ++frame) {
    glfwPollEvents();
    int fb_width = 0, fb_height = 0;
    glfwGetFramebufferSize(context.window(), &fb_width, &fb_height);
    if (fb_width <= 0 || fb_height <= 0) continue;
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    host.NewFrame(fb_width, fb_height, dt);
    ui_frame(fb_width, fb_height, dt);
    frame_target.Resize(fb_width, fb_height);
    frame_target.Bind();
    frame_target.Clear(0.06f, 0.06f, 0.07f, 1.0f);
    host.Render();
    const bool last_frame = quit_after_frames > 0 && frame + 1 >= quit_after_frames;
    if (last_frame && !screenshot.empty()) {
      SaveImage(screenshot, frame_target.ReadPixels());
      std::printf("wrote %s\n", screenshot.c_str());
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, frame_target.framebuffer());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, fb_width, fb_height, 0, 0, fb_width, fb_height, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
    glfwSwapBuffers(context.window());
    if (last_frame) break;
  }
}

// The LRF workbench in a window (a calibench.lrf-dataset.v1 manifest).
int RunLrfGuiWindow(const std::string& dataset, int width, int height,
                    const std::string& screenshot, int quit_after_frames) {
  auto context = OpenWindow(width, height, "Calibench (2D LRF)");
  if (!context) return kInputError;
  ui::LrfController controller;
  controller.Open(dataset);  // a bad manifest shows its error in the window's status line
  ui::ImGuiHost host(context->window());
  ui::LrfWorkbench workbench;
  RunWindowLoop(
      *context, host,
      [&](int w, int h, double dt) {
        for (const ui::LrfIntent& intent :
             workbench.Frame(controller.GetSnapshot(), w, h, ui::LrfLayout::kWorkbench, dt))
          controller.Apply(intent);
      },
      screenshot, quit_after_frames);
  return kOk;
}

int RenderLrfHeadless(const std::string& dataset, const std::string& pair, bool solve,
                      const std::string& view, int width, int height, const std::string& out,
                      gfx::HeadlessBackend backend) {
  ui::LrfLayout layout;
  if (!ui::ParseLrfLayout(view, &layout)) {
    std::fprintf(stderr,
                 "calibench render: for an LRF dataset --view must be scan, depth, 3d or "
                 "workbench\n");
    return kUsage;
  }
  std::string why;
  auto context = gfx::CreateHeadlessContext(backend, &why);
  if (!context) {
    std::fprintf(stderr, "calibench render: no headless OpenGL: %s\n", why.c_str());
    return kInputError;
  }
  ui::LrfController controller;
  if (!controller.Open(dataset)) {
    std::fprintf(stderr, "calibench render: %s\n", controller.GetSnapshot().status_line.c_str());
    return kInputError;
  }
  controller.WaitIdle();
  if (!pair.empty()) {
    const ui::LrfSnapshot s = controller.GetSnapshot();
    int index = -1;
    for (size_t i = 0; i < s.pairs.size(); ++i)
      if (s.pairs[i].id == pair) index = static_cast<int>(i);
    if (index < 0) {
      std::fprintf(stderr, "calibench render: no pair '%s' in %s\n", pair.c_str(), dataset.c_str());
      return kInputError;
    }
    controller.Apply(ui::LrfSelectPair{index});
  }
  if (solve) controller.Apply(ui::LrfRunSolver{});
  controller.WaitIdle();
  ui::ImGuiHost host(nullptr);
  ui::LrfWorkbench workbench;
  SaveImage(out, ui::RenderWorkbenchHeadless(controller, workbench, host, layout, width, height,
                                             /*frames=*/4));
  std::printf("wrote %s (%dx%d, %s, %s)\n", out.c_str(), width, height, view.c_str(),
              context->Description().c_str());
  return kOk;
}

}  // namespace

int RunGuiWindow(const std::string& dataset, const std::string& session, int width, int height,
                 const std::string& screenshot, int quit_after_frames) {
  auto context = OpenWindow(width, height, "Calibench");
  if (!context) return kInputError;
  ui::Controller controller;
  if (!OpenInput(controller, dataset, session, "gui")) return kUsage;
  ui::ImGuiHost host(context->window());
  ui::Workbench workbench;
  RunWindowLoop(
      *context, host,
      [&](int w, int h, double dt) {
        for (const ui::Intent& intent :
             workbench.Frame(controller.GetSnapshot(), w, h, ui::Layout::kWorkbench, dt))
          controller.Apply(intent);
      },
      screenshot, quit_after_frames);
  return kOk;
}

int RunGui(int argc, char** argv) {
  CLI::App app{
      "The Calibench workbench: LiDAR image, camera frame and 3D view; brush, accept or "
      "reject pairs, solve and inspect.",
      "calibench gui"};
  std::string dataset, session, size = "1600x900", screenshot;
  int quit_after_frames = 0;
  app.add_option("--dataset,-d", dataset,
                 "dataset.json or dataset folder, or an LRF manifest (calibench.lrf-dataset.v1)");
  app.add_option("--session,-s", session, "a saved session (calibench.session.v1)");
  app.add_option("--size", size, "window size WxH")->capture_default_str();
  app.add_option("--screenshot", screenshot, "write the last frame to this PNG");
  app.add_option("--quit-after-frames", quit_after_frames, "close after N frames (tests)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  int width = 0, height = 0;
  if (!ParseSize(size, &width, &height)) {
    std::fprintf(stderr, "calibench gui: --size must be WxH, e.g. 1600x900\n");
    return kUsage;
  }
  if (!dataset.empty() && IsLrfManifest(dataset))
    return RunLrfGuiWindow(dataset, width, height, screenshot, quit_after_frames);
  return RunGuiWindow(dataset, session, width, height, screenshot, quit_after_frames);
}

int RenderHeadless(const std::string& dataset, const std::string& session, const std::string& pair,
                   bool solve, const std::string& view, int width, int height,
                   const std::string& out, const std::string& backend_name) {
  ui::Layout layout;
  gfx::HeadlessBackend backend;
  if (!dataset.empty() && IsLrfManifest(dataset)) {
    if (!gfx::ParseHeadlessBackend(backend_name, &backend)) {
      std::fprintf(stderr, "calibench render: --gl must be auto, egl or osmesa\n");
      return kUsage;
    }
    return RenderLrfHeadless(dataset, pair, solve, view, width, height, out, backend);
  }
  if (!ui::ParseLayout(view, &layout)) {
    std::fprintf(stderr, "calibench render: --view must be lidar, camera, 3d or workbench\n");
    return kUsage;
  }
  if (!gfx::ParseHeadlessBackend(backend_name, &backend)) {
    std::fprintf(stderr, "calibench render: --gl must be auto, egl or osmesa\n");
    return kUsage;
  }
  std::string why;
  auto context = gfx::CreateHeadlessContext(backend, &why);
  if (!context) {
    std::fprintf(stderr, "calibench render: no headless OpenGL: %s\n", why.c_str());
    return kInputError;
  }
  ui::Controller controller;
  if (!OpenInput(controller, dataset, session, "render")) return kUsage;
  controller.WaitIdle();
  if (!pair.empty()) {
    const ui::Snapshot s = controller.GetSnapshot();
    int index = -1;
    for (size_t i = 0; i < s.pairs.size(); ++i)
      if (s.pairs[i].id == pair) index = static_cast<int>(i);
    if (index < 0) {
      std::fprintf(stderr, "calibench render: no pair '%s' in %s\n", pair.c_str(),
                   s.dataset_path.string().c_str());
      return kInputError;
    }
    controller.Apply(ui::SelectPair{index});
  }
  if (solve) controller.Apply(ui::RunSolver{});
  controller.WaitIdle();
  ui::ImGuiHost host(nullptr);
  ui::Workbench workbench;
  // A few frames: ImGui sizes tables and windows on the first ones.
  const ImageU8 picture =
      ui::RenderWorkbenchHeadless(controller, workbench, host, layout, width, height, /*frames=*/4);
  SaveImage(out, picture);
  std::printf("wrote %s (%dx%d, %s, %s)\n", out.c_str(), width, height, view.c_str(),
              context->Description().c_str());
  return kOk;
}

int RenderDemoViews(const std::string& dataset, const std::string& out_dir) {
  std::string why;
  auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &why);
  if (!context) {
    std::fprintf(stderr, "calibench demo: no headless OpenGL to render the views: %s\n",
                 why.c_str());
    return kInputError;
  }
  ui::Controller controller;
  controller.OpenDataset(dataset, std::filesystem::path(out_dir) / "calibench.session.json");
  controller.WaitIdle();
  controller.Apply(ui::RunSolver{});
  controller.WaitIdle();
  ui::ImGuiHost host(nullptr);
  const struct {
    ui::Layout layout;
    const char* file;
    int width, height;
  } kViews[] = {{ui::Layout::kWorkbench, "workbench.png", 1600, 900},
                {ui::Layout::kLidarOnly, "view_lidar.png", 800, 450},
                {ui::Layout::kCameraOnly, "view_camera.png", 800, 600},
                {ui::Layout::kSceneOnly, "view_3d.png", 800, 600}};
  for (const auto& view : kViews) {
    ui::Workbench workbench;
    const std::string path = out_dir + "/" + view.file;
    SaveImage(path, ui::RenderWorkbenchHeadless(controller, workbench, host, view.layout,
                                                view.width, view.height, 4));
    std::printf("rendered %s\n", path.c_str());
  }
  std::printf("session: %s/calibench.session.json (open it with `calibench gui --session ...`)\n",
              out_dir.c_str());
  return kOk;
}

int RunRender(int argc, char** argv) {
  CLI::App app{
      "Draw the workbench views to PNG without a window (EGL surfaceless or OSMesa): "
      "exactly what the window shows.",
      "calibench render"};
  std::string dataset, session, pair, view = "workbench", size = "1600x900", out, gl = "auto";
  bool solve = false;
  app.add_option("--dataset,-d", dataset, "dataset.json or dataset folder");
  app.add_option("--session,-s", session, "a saved session");
  app.add_option("--pair", pair, "pair id to show (default: the session's selection)");
  app.add_flag("--solve", solve, "run the solver before drawing");
  app.add_option("--view", view,
                 "lidar | camera | 3d | workbench (LRF datasets: scan | depth | 3d | workbench)")
      ->capture_default_str();
  app.add_option("--size", size, "WxH")->capture_default_str();
  app.add_option("--out,-o", out, "PNG file")->required();
  app.add_option("--gl", gl, "auto | egl | osmesa")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  int width = 0, height = 0;
  if (!ParseSize(size, &width, &height)) {
    std::fprintf(stderr, "calibench render: --size must be WxH, e.g. 1600x900\n");
    return kUsage;
  }
  return RenderHeadless(dataset, session, pair, solve, view, width, height, out, gl);
}

}  // namespace calibench::app
