// Loading the GL entry points of the current context into gl_api.h's function pointers. Kept
// apart from gl_api.h, and free of GL declarations, so that it can be included next to
// <GL/osmesa.h>, which pulls in <GL/gl.h> and its prototypes.
#pragma once

#include <string>

namespace calibench::gfx {

// A context's entry-point lookup (eglGetProcAddress, OSMesaGetProcAddress, glfwGetProcAddress,
// each wrapped to return void*).
using GlProcLoader = void* (*)(const char* name);

// Loads every function of gl_api.h with `get_proc`; the context must be current. Also checks that
// the context is OpenGL 3.3 or newer. The pointers are process-wide: call it again after making
// a context of another backend current (GlContext::MakeCurrent does). Reloads only when
// `get_proc` differs from the last successful call, because each backend's entry points are the
// same for all of its contexts (glvnd and Mesa dispatch on the current context themselves).
// false with *why naming the missing functions or the too-old version.
bool LoadGl(GlProcLoader get_proc, std::string* why);

// "<GL_RENDERER>, OpenGL <GL_VERSION>" of the current context; requires a successful LoadGl.
std::string CurrentGlSummary();

}  // namespace calibench::gfx
