#include "ui/gfx/context.h"

#include <dlfcn.h>

#include <stdexcept>
#include <utility>

#include "ui/gfx/context_internal.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/gl_loader.h"

// No GL header from GLFW: this file makes no GL call (LoadGl and Framebuffer do them).
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace calibench::gfx {
namespace {

// GLFW reports errors through a callback, not a return value; keep the last one for *why.
// GLFW is main-thread only, so these need no lock.
std::string last_glfw_error;
int glfw_windows = 0;  // glfwTerminate with the last window

void RecordGlfwError(int code, const char* description) {
  last_glfw_error = description ? description : ("GLFW error " + std::to_string(code));
}

void* GlfwProc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

void ReleaseGlfw() {
  if (--glfw_windows == 0) glfwTerminate();
}

#if defined(__SANITIZE_ADDRESS__)
#define CALIBENCH_LEAK_CHECKED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CALIBENCH_LEAK_CHECKED 1
#endif
#endif

// Under LeakSanitizer only: Mesa keeps allocations for the life of the process, and eglTerminate
// unloads its driver (swrast_dri.so) before the process exits. LeakSanitizer then reports those
// allocations from "<unknown module>", which no suppression can name, and a test of our GL code
// fails on Mesa's leaks. Pinning the drivers (RTLD_NODELETE) keeps their names in the reports, so
// tests/sanitizers/lsan.supp can list them. Release builds never load anything here.
void PinGlDriversForLeakChecks() {
#if defined(CALIBENCH_LEAK_CHECKED)
  static const bool pinned = [] {
    for (const char* library :
         {"libEGL_mesa.so.0", "libGLX_mesa.so.0", "/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so",
          "/usr/lib/dri/swrast_dri.so", "libOSMesa.so.8"})
      dlopen(library, RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);  // absent ones are fine
    return true;
  }();
  (void)pinned;
#endif
}

}  // namespace

bool ParseHeadlessBackend(const std::string& name, HeadlessBackend* backend) {
  if (name == "auto") {
    *backend = HeadlessBackend::kAuto;
  } else if (name == "egl") {
    *backend = HeadlessBackend::kEgl;
  } else if (name == "osmesa") {
    *backend = HeadlessBackend::kOsMesa;
  } else {
    return false;
  }
  return true;
}

std::unique_ptr<GlContext> CreateHeadlessContext(HeadlessBackend backend, std::string* why) {
  PinGlDriversForLeakChecks();
  std::string egl_why, osmesa_why;
  std::unique_ptr<GlContext> context;
  if (backend == HeadlessBackend::kEgl || backend == HeadlessBackend::kAuto) {
    context = internal::CreateEglContext(&egl_why);
    if (context || backend == HeadlessBackend::kEgl) {
      if (!context && why) *why = egl_why;
      return context;
    }
  }
  context = internal::CreateOsMesaContext(&osmesa_why);
  if (!context && why) *why = egl_why.empty() ? osmesa_why : egl_why + "; " + osmesa_why;
  return context;
}

void internal::HeadlessContext::MakeCurrent() {
  std::string why;
  if (!TryMakeCurrent(&why)) throw std::runtime_error(description_ + ": " + why);
}

std::unique_ptr<GlContext> internal::HeadlessContext::Activate(
    std::unique_ptr<HeadlessContext> context, const std::string& label, std::string* why) {
  std::string reason;
  if (!context->TryMakeCurrent(&reason)) {
    *why = label + ": " + reason;
    return nullptr;
  }
  context->description_ = label + ": " + CurrentGlSummary();
  return context;
}

std::unique_ptr<WindowContext> WindowContext::Create(int width, int height,
                                                     const std::string& title, std::string* why) {
  std::string reason;
  if (!why) why = &reason;
  PinGlDriversForLeakChecks();
  glfwSetErrorCallback(RecordGlfwError);
  last_glfw_error.clear();
  if (glfw_windows == 0 && !glfwInit()) {
    *why = "GLFW: cannot initialise (" + last_glfw_error + ")";
    return nullptr;
  }
  ++glfw_windows;
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (window == nullptr) {
    *why = "GLFW: cannot open a " + std::to_string(width) + "x" + std::to_string(height) +
           " window with an OpenGL 3.3 core context (" + last_glfw_error + ")";
    ReleaseGlfw();
    return nullptr;
  }
  std::unique_ptr<WindowContext> context(new WindowContext(window));
  context->InstallEventCounters();
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);  // vsync: an animating workbench need not outrun the screen
  if (!LoadGl(GlfwProc, why)) {
    *why = "GLFW window: " + *why;
    return nullptr;
  }
  context->description_ = "GLFW window: " + CurrentGlSummary();
  return context;
}

WindowContext::~WindowContext() {
  glfwDestroyWindow(window_);
  ReleaseGlfw();
}

void WindowContext::MakeCurrent() {
  // Release first: a "still current" GLX context would not be re-bound, while an OSMesa context
  // made current meanwhile owns Mesa's GL dispatch (see context_egl.cpp).
  if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
  glfwMakeContextCurrent(window_);
  std::string why;
  if (!LoadGl(GlfwProc, &why)) throw std::runtime_error("GLFW window: " + why);
}

std::string WindowContext::Description() const { return description_; }

void WindowContext::PollEvents() { glfwPollEvents(); }

void WindowContext::WaitEvents(double timeout_s) {
  if (timeout_s > 0)
    glfwWaitEventsTimeout(timeout_s);
  else
    glfwPollEvents();
}

void WindowContext::CountEvent(GLFWwindow* window) {
  ++static_cast<WindowContext*>(glfwGetWindowUserPointer(window))->events_;
}

void WindowContext::InstallEventCounters() {
  glfwSetWindowUserPointer(window_, this);
  // ImGui's GLFW backend (1.86) polls the pointer position and installs no cursor callback; it
  // keeps the callbacks below that were set before it and calls them from its own.
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double, double) { CountEvent(w); });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int, int, int) { CountEvent(w); });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double) { CountEvent(w); });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int, int, int, int) { CountEvent(w); });
  glfwSetCharCallback(window_, [](GLFWwindow* w, unsigned int) { CountEvent(w); });
  glfwSetCursorEnterCallback(window_, [](GLFWwindow* w, int) { CountEvent(w); });
  glfwSetWindowFocusCallback(window_, [](GLFWwindow* w, int) { CountEvent(w); });
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int, int) { CountEvent(w); });
  glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) { CountEvent(w); });
  glfwSetWindowIconifyCallback(window_, [](GLFWwindow* w, int) { CountEvent(w); });
  glfwSetDropCallback(window_, [](GLFWwindow* w, int count, const char** paths) {
    auto* self = static_cast<WindowContext*>(glfwGetWindowUserPointer(w));
    for (int i = 0; i < count; ++i) self->dropped_.emplace_back(paths[i]);
    CountEvent(w);
  });
}

void WindowContext::RequestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

std::vector<std::string> WindowContext::TakeDroppedPaths() { return std::exchange(dropped_, {}); }

void WindowContext::DeliverDrop(const std::vector<std::string>& paths) {
  // GLFW has no getter: setting a callback returns the one it replaces.
  const GLFWdropfun installed = glfwSetDropCallback(window_, nullptr);
  glfwSetDropCallback(window_, installed);
  std::vector<const char*> pointers;
  for (const std::string& path : paths) pointers.push_back(path.c_str());
  if (installed) installed(window_, static_cast<int>(pointers.size()), pointers.data());
}

bool WindowContext::ShouldClose() const { return glfwWindowShouldClose(window_); }

void WindowContext::FramebufferSize(int* width, int* height) const {
  glfwGetFramebufferSize(window_, width, height);
}

void WindowContext::Present(const Framebuffer& frame) {
  frame.BlitToDefault();
  glfwSwapBuffers(window_);
}

}  // namespace calibench::gfx
