// Dear ImGui set-up shared by the window and the headless renderer: context, theme, font,
// OpenGL3 backend (and the GLFW backend for a window). The headless host feeds display size, time
// and input itself, so tests can drive the panels frame by frame without a window.
#pragma once

#include <memory>
#include <string>

#include "core/image.h"
#include "ui/controller.h"
#include "ui/workbench.h"

struct GLFWwindow;

namespace calibench::ui {

class ImGuiHost {
 public:
  // Requires a current GL context. window == nullptr: headless (no platform backend).
  explicit ImGuiHost(GLFWwindow* window);
  ~ImGuiHost();
  ImGuiHost(const ImGuiHost&) = delete;
  ImGuiHost& operator=(const ImGuiHost&) = delete;

  // Starts a frame. Headless: display size and delta time come from the arguments.
  void NewFrame(int width, int height, double delta_seconds);
  // Renders the frame's draw data into the currently bound framebuffer.
  void Render();

 private:
  bool windowed_ = false;
};

// The dark theme and DejaVu Sans (from fonts-dejavu-core; ImGui's built-in font otherwise).
void ApplyThemeAndFont();

// Runs `frames` workbench frames headless against the controller (waiting for its worker before
// each) and returns the last frame as a picture: exactly what the window would show.
ImageU8 RenderWorkbenchHeadless(Controller& controller, Workbench& workbench, ImGuiHost& host,
                                Layout layout, int width, int height, int frames);

}  // namespace calibench::ui
