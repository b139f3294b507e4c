// Dear ImGui set-up shared by the window and the headless renderer: context, theme, font,
// OpenGL3 backend (and the GLFW backend for a window). The headless host feeds display size, time
// and input itself, so tests can drive the panels frame by frame without a window
// (RenderWorkbenchHeadless below; headless_render.h prepares what such a render shows).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "core/base/image.h"

struct GLFWwindow;

namespace calibench::gfx {
class Framebuffer;
}

namespace calibench::ui {

class RedrawRegions;
class RegionRedraw;

class ImGuiHost {
 public:
  // Requires a current GL context. window == nullptr: headless (no platform backend).
  explicit ImGuiHost(GLFWwindow* window);
  ~ImGuiHost();
  ImGuiHost(const ImGuiHost&) = delete;
  ImGuiHost& operator=(const ImGuiHost&) = delete;

  // Starts a frame. Headless: display size and delta time come from the arguments.
  void NewFrame(int width, int height, double delta_seconds);
  // One whole frame drawn into `target` (resized to width x height): NewFrame, build_frame()
  // (the frame's ImGui calls), then the draw data over the workbench's background. When `target`
  // still holds this host's last frame, only the regions that changed are repainted
  // (redraw_regions.h); the picture is the same either way.
  void DrawFrame(gfx::Framebuffer& target, int width, int height, double delta_seconds,
                 const std::function<void()>& build_frame);
  // Pixels the last DrawFrame repainted: 0 when nothing on screen changed.
  long long last_repainted_pixels() const { return last_repainted_pixels_; }
  // false: every frame repaints the whole target (the reference the region repaint is tested
  // against).
  void set_repaint_only_changes(bool on) { repaint_only_changes_ = on; }

 private:
  bool windowed_ = false;
  std::unique_ptr<RedrawRegions> regions_;
  std::unique_ptr<RegionRedraw> region_redraw_;
  // The target of the last frame and its content version after it (gfx::TextureVersion).
  std::uint32_t drawn_texture_ = 0;
  std::uint64_t drawn_version_ = 0;
  long long last_repainted_pixels_ = 0;
  bool repaint_only_changes_ = true;
};

// The dark theme and DejaVu Sans (from fonts-dejavu-core; ImGui's built-in font otherwise).
void ApplyThemeAndFont();

// Runs `frames` ImGui frames headless, each built by build_frame(), into an offscreen framebuffer
// and returns the last one as a picture: exactly what the window would show.
ImageU8 RenderFramesHeadless(ImGuiHost& host, int width, int height, int frames,
                             const std::function<void()>& build_frame);

// A workbench (either method's) driven headless against its controller, waiting for the
// controller's worker before each frame and applying the intents the panels return.
template <typename Controller, typename Workbench, typename Layout>
ImageU8 RenderWorkbenchHeadless(Controller& controller, Workbench& workbench, ImGuiHost& host,
                                Layout layout, int width, int height, int frames) {
  return RenderFramesHeadless(host, width, height, frames, [&] {
    controller.WaitIdle();
    const auto snapshot = controller.GetSnapshot();
    for (const auto& intent : workbench.Frame(snapshot, width, height, layout, 1.0 / 60.0))
      controller.Apply(intent);
  });
}

}  // namespace calibench::ui
