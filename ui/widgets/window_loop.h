// The workbench window: a GLFW window whose frames are drawn offscreen and then presented, the
// same way RenderWorkbenchHeadless (imgui_host.h) draws them, so a screenshot reads exactly what
// is shown.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/base/image.h"

namespace calibench::gfx {
class WindowContext;
}

namespace calibench::ui {

class ImGuiHost;

struct WindowOptions {
  int width = 1600, height = 900;  // pixels
  std::string title = "Calibench";
  int quit_after_frames = 0;        // > 0: close after that many frames (tests)
  bool capture_last_frame = false;  // with quit_after_frames: keep that frame's picture
};

// The window, its GL context (current) and its ImGui host.
class Window {
 public:
  // nullptr with *why when no window opens (no display?).
  static std::unique_ptr<Window> Open(const WindowOptions& options, std::string* why);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  // Runs frames until the user closes the window (or quit_after_frames):
  // frame(width, height, seconds_since_last_frame) issues the ImGui calls of one frame. Returns
  // the last frame's picture with capture_last_frame, when the run reached it.
  std::optional<ImageU8> Run(const std::function<void(int, int, double)>& frame);

 private:
  Window(const WindowOptions& options, std::unique_ptr<gfx::WindowContext> context);
  WindowOptions options_;
  std::unique_ptr<gfx::WindowContext> context_;
  std::unique_ptr<ImGuiHost> host_;  // destroyed before the context
};

// How a workbench window run ended.
struct WindowRun {
  bool opened = false;  // false: no window, see `why`
  std::string why;
  std::optional<ImageU8> last_frame;  // see Window::Run
};

// A workbench (either method's) in a window against its controller, applying the intents its
// panels return. The workbench is made once the window's context is current (it owns GL
// resources).
template <typename Workbench, typename Controller, typename Layout>
WindowRun RunWorkbenchWindow(const WindowOptions& options, Controller& controller, Layout layout) {
  WindowRun run;
  const auto window = Window::Open(options, &run.why);
  if (!window) return run;
  run.opened = true;
  Workbench workbench;
  run.last_frame = window->Run([&](int width, int height, double seconds) {
    for (const auto& intent :
         workbench.Frame(controller.GetSnapshot(), width, height, layout, seconds))
      controller.Apply(intent);
  });
  return run;
}

}  // namespace calibench::ui
