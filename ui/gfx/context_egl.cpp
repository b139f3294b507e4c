// EGL without a window: the headless path of `calibench render` and of the screenshot tests.
#include <map>
#include <mutex>
#include <sstream>
#include <string_view>
#include <vector>

#include "ui/gfx/context_internal.h"
#include "ui/gfx/gl_loader.h"

// EGL_NO_X11 keeps Xlib out of the EGL headers.
#define EGL_NO_X11
#include <EGL/egl.h>
#include <EGL/eglext.h>

namespace calibench::gfx::internal {
namespace {

std::string EglError() {
  const EGLint code = eglGetError();
  switch (code) {
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    default:
      return "EGL error 0x" + (std::ostringstream() << std::hex << code).str();
  }
}

bool HasExtension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  std::string_view rest(list);
  while (!rest.empty()) {
    const size_t end = rest.find(' ');
    if (rest.substr(0, end) == name) return true;
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  return false;
}

void* EglProc(const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }

// eglGetPlatformDisplay hands every caller the same EGLDisplay, and eglTerminate would pull it
// from under all contexts on it: count the users and terminate with the last one.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

bool AcquireDisplay(EGLDisplay display, std::string* why) {
  std::lock_guard<std::mutex> lock(display_mutex);
  if (display_users[display] == 0) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
      display_users.erase(display);
      *why = "eglInitialize failed (" + EglError() + ")";
      return false;
    }
  }
  ++display_users[display];
  return true;
}

void ReleaseDisplay(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(display_mutex);
  if (--display_users[display] == 0) {
    display_users.erase(display);
    eglTerminate(display);
  }
}

class EglContext final : public HeadlessContext {
 public:
  // Takes over one AcquireDisplay() reference and the context.
  EglContext(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}
  ~EglContext() override {
    if (eglGetCurrentContext() == context_) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(display_, context_);
    ReleaseDisplay(display_);
  }

  bool TryMakeCurrent(std::string* why) override {
    // The bound client API is per thread: another library may have bound GLES in between.
    eglBindAPI(EGL_OPENGL_API);
    // If EGL believes the context is current already, eglMakeCurrent does nothing; but an OSMesa
    // context made current meanwhile has taken over Mesa's GL dispatch (libglapi, shared by
    // both), and GL calls would go to it. Releasing first forces a real switch.
    if (eglGetCurrentContext() == context_) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      *why = "eglMakeCurrent without a surface failed (" + EglError() + ")";
      return false;
    }
    return LoadGl(EglProc, why);
  }

 private:
  EGLDisplay display_;
  EGLContext context_;
};

EGLConfig ChooseConfig(EGLDisplay display, const char* display_extensions, bool* ok) {
  // EGL_SURFACE_TYPE 0: no surface kind is needed (the default would demand a window config,
  // which a surfaceless display does not have).
  // clang-format off
  const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                               EGL_SURFACE_TYPE, 0,
                               EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                               EGL_NONE};
  // clang-format on
  EGLConfig config = nullptr;
  EGLint count = 0;
  *ok = true;
  if (eglChooseConfig(display, attributes, &config, 1, &count) && count > 0) return config;
  *ok = HasExtension(display_extensions, "EGL_KHR_no_config_context");
  return EGL_NO_CONFIG_KHR;
}

// One display tried to the end: a current, loaded GL 3.3 core context, or nullptr and *why.
std::unique_ptr<GlContext> TryDisplay(EGLDisplay display, const std::string& label,
                                      std::string* why) {
  if (display == EGL_NO_DISPLAY) {
    *why = label + ": no display (" + EglError() + ")";
    return nullptr;
  }
  std::string reason;
  if (!AcquireDisplay(display, &reason)) {
    *why = label + ": " + reason;
    return nullptr;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  bool config_ok = false;
  EGLConfig config = nullptr;
  EGLContext context = EGL_NO_CONTEXT;
  if (!HasExtension(extensions, "EGL_KHR_surfaceless_context")) {
    reason = "no EGL_KHR_surfaceless_context";
  } else if (!eglBindAPI(EGL_OPENGL_API)) {
    reason = "desktop OpenGL is not supported (" + EglError() + ")";
  } else if (config = ChooseConfig(display, extensions, &config_ok); !config_ok) {
    reason = "no OpenGL-renderable config";
  } else {
    // clang-format off
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_NONE};
    // clang-format on
    context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    if (context == EGL_NO_CONTEXT) reason = "no GL 3.3 core context (" + EglError() + ")";
  }
  if (context == EGL_NO_CONTEXT) {
    ReleaseDisplay(display);
    *why = label + ": " + reason;
    return nullptr;
  }
  return HeadlessContext::Activate(std::make_unique<EglContext>(display, context), label, why);
}

}  // namespace

std::unique_ptr<GlContext> CreateEglContext(std::string* why) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(EglProc("eglGetPlatformDisplayEXT"));
  if (!HasExtension(client_extensions, "EGL_EXT_platform_base") || !get_platform_display) {
    *why = "EGL: no EGL_EXT_platform_base (libEGL without a vendor driver, or too old)";
    return nullptr;
  }
  std::vector<std::string> failures;
  std::string reason;
  // Mesa's surfaceless platform first: llvmpipe here, the Mesa GPU driver where there is one.
  if (HasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
    auto context = TryDisplay(
        get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
        "EGL surfaceless", &reason);
    if (context) return context;
    failures.push_back(reason);
  } else {
    failures.push_back("no EGL_MESA_platform_surfaceless");
  }
  // Then the device platform, which is how NVIDIA's EGL offers its GPUs without a window system.
  const auto query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(EglProc("eglQueryDevicesEXT"));
  if (HasExtension(client_extensions, "EGL_EXT_platform_device") && query_devices) {
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (!query_devices(16, devices, &count)) count = 0;
    for (EGLint i = 0; i < count; ++i) {
      auto context = TryDisplay(get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr),
                                "EGL device " + std::to_string(i), &reason);
      if (context) return context;
      failures.push_back(reason);
    }
    if (count == 0) failures.push_back("EGL lists no devices");
  } else {
    failures.push_back("no EGL_EXT_platform_device");
  }
  *why = "EGL: no GL 3.3 core context without a surface (";
  for (size_t i = 0; i < failures.size(); ++i) *why += (i ? "; " : "") + failures[i];
  *why += ")";
  return nullptr;
}

}  // namespace calibench::gfx::internal
