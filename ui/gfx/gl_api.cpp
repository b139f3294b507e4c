#include "ui/gfx/gl_api.h"

#include <mutex>
#include <string_view>

#define CALIBENCH_GL_DEFINE_POINTER(type, name) type name = nullptr;
CALIBENCH_GL_FUNCTIONS(CALIBENCH_GL_DEFINE_POINTER)
#undef CALIBENCH_GL_DEFINE_POINTER

namespace calibench::gfx {
namespace {

// A function listed in CALIBENCH_GL_FUNCTIONS without its `#define glFoo calibench_glFoo` would
// define a global named glFoo, which would clash with the glFoo that libOSMesa exports.
#define CALIBENCH_GL_STRINGIZE(x) #x
#define CALIBENCH_GL_EXPANDED_NAME(x) CALIBENCH_GL_STRINGIZE(x)
#define CALIBENCH_GL_CHECK_MACRO(type, name)                                              \
  static_assert(std::string_view(CALIBENCH_GL_EXPANDED_NAME(name)) == "calibench_" #name, \
                "gl_api.h: missing #define " #name " calibench_" #name);
CALIBENCH_GL_FUNCTIONS(CALIBENCH_GL_CHECK_MACRO)
#undef CALIBENCH_GL_CHECK_MACRO

std::mutex loader_mutex;
GlProcLoader loaded_with = nullptr;  // guarded by loader_mutex

std::string LoadAll(GlProcLoader get_proc) {
  std::string missing;
  // #name is the unexpanded spelling ("glClear"): the symbol the context is asked for.
#define CALIBENCH_GL_LOAD(type, name)             \
  name = reinterpret_cast<type>(get_proc(#name)); \
  if (name == nullptr) missing += (missing.empty() ? "" : ", ") + std::string(#name);
  CALIBENCH_GL_FUNCTIONS(CALIBENCH_GL_LOAD)
#undef CALIBENCH_GL_LOAD
  return missing;
}

std::string GlString(GLenum name) {
  const GLubyte* text = glGetString(name);
  return text ? reinterpret_cast<const char*>(text) : "(unknown)";
}

}  // namespace

bool LoadGl(GlProcLoader get_proc, std::string* why) {
  std::lock_guard<std::mutex> lock(loader_mutex);
  if (get_proc != loaded_with) {
    loaded_with = nullptr;
    const std::string missing = LoadAll(get_proc);
    if (!missing.empty()) {
      if (why) *why = "the GL context does not provide: " + missing;
      return false;
    }
    loaded_with = get_proc;
  }
  // GL_MAJOR_VERSION exists from 3.0 on; an older context leaves the values at 0.
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 33) {
    if (why) {
      *why = "OpenGL 3.3 core is required, the context is " + GlString(GL_VERSION) + " (" +
             GlString(GL_RENDERER) + ")";
    }
    return false;
  }
  return true;
}

std::string CurrentGlSummary() {
  return GlString(GL_RENDERER) + ", OpenGL " + GlString(GL_VERSION);
}

}  // namespace calibench::gfx
