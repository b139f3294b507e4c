// The workbench window: a GLFW window whose frames are drawn offscreen and then presented, the
// same way RenderWorkbenchHeadless (imgui_host.h) draws them, so a screenshot reads exactly what
// is shown.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"

namespace calibench::gfx {
class WindowContext;
}

namespace calibench::ui {

class ImGuiHost;

struct WindowOptions {
  int width = 1600, height = 900;  // pixels
  std::string title = "Calibench";
  // > 0: close after that many frames, drawn back to back (tests of what a frame shows).
  int quit_after_frames = 0;
  bool capture_last_frame = false;  // keep the last drawn frame's picture
  // > 0: close after this long (seconds), drawing as a user's session does (tests of idling).
  double quit_after_seconds = 0.0;
  // Delivered through the window's drop callback once the first frames are drawn, one path per
  // frame, as a window system would (tests of drag and drop); frames keep coming until all are.
  std::vector<std::string> test_drops;
  // When set: one line per frame to this file, "<seconds since start> <milliseconds>" (how long
  // the frame took to draw and show: a frozen GUI shows as long frames).
  std::string frame_log;
  // > 0: every this many seconds, the next frame drawn is also written to
  // `<screenshots_prefix>_<n>.png` (n from 1): what a capture session looked like as it went.
  double screenshot_every_s = 0.0;
  std::string screenshots_prefix;
};

// What a window run drew: every frame, and those drawn when nothing had moved for a second (no
// input, nothing animating), which a window that idles at zero never draws.
struct FrameStats {
  int frames = 0;
  int quiet_frames = 0;
  double max_frame_ms = 0.0;  // the longest frame, drawn and shown
  int slow_frames = 0;        // frames over 50 ms after the first (which lay the window out)
};

// The window, its GL context (current) and its ImGui host.
class Window {
 public:
  // nullptr with *why when no window opens (no display?).
  static std::unique_ptr<Window> Open(const WindowOptions& options, std::string* why);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  // Runs frames until the user closes the window (or quit_after_frames / quit_after_seconds):
  // frame(width, height, seconds_since_last_frame) issues the ImGui calls of one frame and says
  // whether the next one would differ without input (a worker or a replay running). A frame is
  // drawn only after input (and a few more, for ImGui to settle hover and layout), while the
  // workbench animates (at most 60 per second), and every quarter second while a text field
  // takes typing (its cursor blinks); otherwise the loop sleeps in the window system.
  // Returns the last frame's picture with capture_last_frame.
  // changed (optional): whether what the window shows changed since the last frame without
  // input (a thread following a capture); polled every tenth of a second while idle.
  std::optional<ImageU8> Run(const std::function<bool(int, int, double)>& frame,
                             const std::function<bool()>& changed = {});
  const FrameStats& stats() const { return stats_; }
  // Files and folders dropped onto the window since the last call (call from `frame`).
  std::vector<std::string> TakeDroppedPaths();
  // Drives the window's drop callback as the window system would (tests).
  void DeliverDrop(const std::vector<std::string>& paths);
  // Ends Run after the frame being drawn (the File menu's Quit).
  void RequestClose();

 private:
  Window(const WindowOptions& options, std::unique_ptr<gfx::WindowContext> context);
  WindowOptions options_;
  FrameStats stats_;
  std::unique_ptr<gfx::WindowContext> context_;
  std::unique_ptr<ImGuiHost> host_;  // destroyed before the context
};

// How a workbench window run ended.
struct WindowRun {
  bool opened = false;  // false: no window, see `why`
  std::string why;
  std::optional<ImageU8> last_frame;  // see Window::Run
  FrameStats stats;
};

}  // namespace calibench::ui
