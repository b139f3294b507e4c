// OpenGL 3.3 core contexts: a GLFW window (on screen), EGL surfaceless (headless; Mesa llvmpipe
// here, NVIDIA EGL where a GPU exists) and OSMesa (headless fallback). GL entry points are loaded
// per context through gl_api.h, so the same binary draws with any of them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct GLFWwindow;

namespace calibench::gfx {

class Framebuffer;

enum class HeadlessBackend { kAuto, kEgl, kOsMesa };
// "auto", "egl", "osmesa"; false for anything else.
bool ParseHeadlessBackend(const std::string& name, HeadlessBackend* backend);

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual void MakeCurrent() = 0;
  // e.g. "EGL surfaceless: Mesa llvmpipe (LLVM 15), OpenGL 4.5 core".
  virtual std::string Description() const = 0;
};

// A headless context with GL loaded and current. Rendering goes into gfx::Framebuffer objects.
// nullptr with *why when the backend is unavailable (kAuto tries EGL, then OSMesa).
std::unique_ptr<GlContext> CreateHeadlessContext(HeadlessBackend backend, std::string* why);

// A GLFW window with a GL 3.3 core context, GL loaded and current. nullptr with *why when no
// display is available. The window is destroyed with the context.
class WindowContext : public GlContext {
 public:
  static std::unique_ptr<WindowContext> Create(int width, int height, const std::string& title,
                                               std::string* why);
  ~WindowContext() override;
  void MakeCurrent() override;
  std::string Description() const override;
  GLFWwindow* window() const { return window_; }

  // The window's frame loop: handles pending events (input goes to the callbacks, ImGui's
  // included), tells whether the user asked to close the window, and its framebuffer size
  // (pixels; 0 while minimised).
  void PollEvents();
  // Sleeps until an event arrives or `timeout_s` passes, then handles the events as PollEvents.
  void WaitEvents(double timeout_s);
  // How many input and window events (pointer, buttons, wheel, keys, text, resize, focus,
  // expose) have arrived: the frame loop draws only when it moves, or while something animates.
  std::uint64_t EventCount() const { return events_; }
  bool ShouldClose() const;
  void FramebufferSize(int* width, int* height) const;
  // Shows `frame`, drawn offscreen at the framebuffer size: copies it into the back buffer and
  // swaps (waiting for vsync).
  void Present(const Framebuffer& frame);
  // Files and folders dropped onto the window since the last call (a drop is an event).
  std::vector<std::string> TakeDroppedPaths();
  // Asks the loop to end, as the window's close button does.
  void RequestClose();
  // Calls the drop callback installed on the GLFW window, as GLFW does when the window system
  // delivers a drop: what a test of drag and drop drives without a window manager.
  void DeliverDrop(const std::vector<std::string>& paths);

 private:
  explicit WindowContext(GLFWwindow* window) : window_(window) {}
  // Counts events; installed before ImGui's backend, which chains to them.
  void InstallEventCounters();
  static void CountEvent(GLFWwindow* window);
  GLFWwindow* window_ = nullptr;
  std::uint64_t events_ = 0;
  std::vector<std::string> dropped_;
  std::string description_;
};

}  // namespace calibench::gfx
