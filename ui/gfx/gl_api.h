// Our own OpenGL 3.3 core loader. The same binary draws on a GLFW (GLX) window, an EGL
// surfaceless context and an OSMesa context; OSMesa is not dispatched by libglvnd, so calling
// libOpenGL's glFoo directly would never reach it. Instead every GL function we (and Dear ImGui's
// OpenGL3 backend) call is a function pointer, filled per backend by LoadGl(), and `glFoo` is a
// macro for the pointer `calibench_glFoo`, so code keeps writing glFoo(...).
//
// Include this before any other GL header (it replaces <GL/gl.h>; <GLFW/glfw3.h> is fine after
// it). A GL function not in CALIBENCH_GL_FUNCTIONS fails to compile: add it to both lists below.
#pragma once

#if defined(__gl_h_) || defined(__GL_H__) || defined(GL_GLEXT_PROTOTYPES)
#error "ui/gfx/gl_api.h must be included before any other GL header, without GL_GLEXT_PROTOTYPES"
#endif

// GLFW must not pull in <GL/gl.h>, whose prototypes would collide with the macros below.
#ifndef GLFW_INCLUDE_NONE
#define GLFW_INCLUDE_NONE
#endif

#include <GL/glcorearb.h>  // types, constants and PFN...PROC typedefs; no prototypes

#include "ui/gfx/gl_loader.h"

// Keep the legacy headers out for the rest of the translation unit (the same guard trick glad
// uses): they would declare glFoo prototypes that the macros below turn into redeclarations.
#define __gl_h_
#define __GL_H__
#define __gl_glext_h_

// clang-format off
// X(type, name) for every GL entry point we load. ImGui 1.86's imgui_impl_opengl3.cpp uses a
// subset of these; the rest are ours (framebuffers, renderers, tests).
#define CALIBENCH_GL_FUNCTIONS(X) \
  X(PFNGLACTIVETEXTUREPROC, glActiveTexture) \
  X(PFNGLATTACHSHADERPROC, glAttachShader) \
  X(PFNGLBINDBUFFERPROC, glBindBuffer) \
  X(PFNGLBINDFRAMEBUFFERPROC, glBindFramebuffer) \
  X(PFNGLBINDRENDERBUFFERPROC, glBindRenderbuffer) \
  X(PFNGLBINDSAMPLERPROC, glBindSampler) \
  X(PFNGLBINDTEXTUREPROC, glBindTexture) \
  X(PFNGLBINDVERTEXARRAYPROC, glBindVertexArray) \
  X(PFNGLBLENDEQUATIONPROC, glBlendEquation) \
  X(PFNGLBLENDEQUATIONSEPARATEPROC, glBlendEquationSeparate) \
  X(PFNGLBLENDFUNCPROC, glBlendFunc) \
  X(PFNGLBLENDFUNCSEPARATEPROC, glBlendFuncSeparate) \
  X(PFNGLBLITFRAMEBUFFERPROC, glBlitFramebuffer) \
  X(PFNGLBUFFERDATAPROC, glBufferData) \
  X(PFNGLBUFFERSUBDATAPROC, glBufferSubData) \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, glCheckFramebufferStatus) \
  X(PFNGLCLEARPROC, glClear) \
  X(PFNGLCLEARCOLORPROC, glClearColor) \
  X(PFNGLCLEARDEPTHPROC, glClearDepth) \
  X(PFNGLCOMPILESHADERPROC, glCompileShader) \
  X(PFNGLCREATEPROGRAMPROC, glCreateProgram) \
  X(PFNGLCREATESHADERPROC, glCreateShader) \
  X(PFNGLDELETEBUFFERSPROC, glDeleteBuffers) \
  X(PFNGLDELETEFRAMEBUFFERSPROC, glDeleteFramebuffers) \
  X(PFNGLDELETEPROGRAMPROC, glDeleteProgram) \
  X(PFNGLDELETERENDERBUFFERSPROC, glDeleteRenderbuffers) \
  X(PFNGLDELETESHADERPROC, glDeleteShader) \
  X(PFNGLDELETETEXTURESPROC, glDeleteTextures) \
  X(PFNGLDELETEVERTEXARRAYSPROC, glDeleteVertexArrays) \
  X(PFNGLDEPTHFUNCPROC, glDepthFunc) \
  X(PFNGLDEPTHMASKPROC, glDepthMask) \
  X(PFNGLDETACHSHADERPROC, glDetachShader) \
  X(PFNGLDISABLEPROC, glDisable) \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, glDisableVertexAttribArray) \
  X(PFNGLDRAWARRAYSPROC, glDrawArrays) \
  X(PFNGLDRAWELEMENTSPROC, glDrawElements) \
  X(PFNGLDRAWELEMENTSBASEVERTEXPROC, glDrawElementsBaseVertex) \
  X(PFNGLENABLEPROC, glEnable) \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, glEnableVertexAttribArray) \
  X(PFNGLFINISHPROC, glFinish) \
  X(PFNGLFLUSHPROC, glFlush) \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, glFramebufferRenderbuffer) \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, glFramebufferTexture2D) \
  X(PFNGLGENBUFFERSPROC, glGenBuffers) \
  X(PFNGLGENFRAMEBUFFERSPROC, glGenFramebuffers) \
  X(PFNGLGENRENDERBUFFERSPROC, glGenRenderbuffers) \
  X(PFNGLGENTEXTURESPROC, glGenTextures) \
  X(PFNGLGENVERTEXARRAYSPROC, glGenVertexArrays) \
  X(PFNGLGETATTRIBLOCATIONPROC, glGetAttribLocation) \
  X(PFNGLGETERRORPROC, glGetError) \
  X(PFNGLGETFLOATVPROC, glGetFloatv) \
  X(PFNGLGETINTEGERVPROC, glGetIntegerv) \
  X(PFNGLGETPROGRAMINFOLOGPROC, glGetProgramInfoLog) \
  X(PFNGLGETPROGRAMIVPROC, glGetProgramiv) \
  X(PFNGLGETSHADERINFOLOGPROC, glGetShaderInfoLog) \
  X(PFNGLGETSHADERIVPROC, glGetShaderiv) \
  X(PFNGLGETSTRINGPROC, glGetString) \
  X(PFNGLGETSTRINGIPROC, glGetStringi) \
  X(PFNGLGETUNIFORMLOCATIONPROC, glGetUniformLocation) \
  X(PFNGLISENABLEDPROC, glIsEnabled) \
  X(PFNGLLINEWIDTHPROC, glLineWidth) \
  X(PFNGLLINKPROGRAMPROC, glLinkProgram) \
  X(PFNGLPIXELSTOREIPROC, glPixelStorei) \
  X(PFNGLPOLYGONMODEPROC, glPolygonMode) \
  X(PFNGLREADBUFFERPROC, glReadBuffer) \
  X(PFNGLREADPIXELSPROC, glReadPixels) \
  X(PFNGLRENDERBUFFERSTORAGEPROC, glRenderbufferStorage) \
  X(PFNGLSCISSORPROC, glScissor) \
  X(PFNGLSHADERSOURCEPROC, glShaderSource) \
  X(PFNGLTEXIMAGE2DPROC, glTexImage2D) \
  X(PFNGLTEXPARAMETERIPROC, glTexParameteri) \
  X(PFNGLTEXPARAMETERIVPROC, glTexParameteriv) \
  X(PFNGLTEXSUBIMAGE2DPROC, glTexSubImage2D) \
  X(PFNGLUNIFORM1FPROC, glUniform1f) \
  X(PFNGLUNIFORM1IPROC, glUniform1i) \
  X(PFNGLUNIFORM2IPROC, glUniform2i) \
  X(PFNGLUNIFORM4FPROC, glUniform4f) \
  X(PFNGLUNIFORMMATRIX4FVPROC, glUniformMatrix4fv) \
  X(PFNGLUSEPROGRAMPROC, glUseProgram) \
  X(PFNGLVERTEXATTRIBPOINTERPROC, glVertexAttribPointer) \
  X(PFNGLVIEWPORTPROC, glViewport)

// glFoo -> calibench_glFoo, one per entry above (gl_api.cpp checks that the two lists agree).
#define glActiveTexture calibench_glActiveTexture
#define glAttachShader calibench_glAttachShader
#define glBindBuffer calibench_glBindBuffer
#define glBindFramebuffer calibench_glBindFramebuffer
#define glBindRenderbuffer calibench_glBindRenderbuffer
#define glBindSampler calibench_glBindSampler
#define glBindTexture calibench_glBindTexture
#define glBindVertexArray calibench_glBindVertexArray
#define glBlendEquation calibench_glBlendEquation
#define glBlendEquationSeparate calibench_glBlendEquationSeparate
#define glBlendFunc calibench_glBlendFunc
#define glBlendFuncSeparate calibench_glBlendFuncSeparate
#define glBlitFramebuffer calibench_glBlitFramebuffer
#define glBufferData calibench_glBufferData
#define glBufferSubData calibench_glBufferSubData
#define glCheckFramebufferStatus calibench_glCheckFramebufferStatus
#define glClear calibench_glClear
#define glClearColor calibench_glClearColor
#define glClearDepth calibench_glClearDepth
#define glCompileShader calibench_glCompileShader
#define glCreateProgram calibench_glCreateProgram
#define glCreateShader calibench_glCreateShader
#define glDeleteBuffers calibench_glDeleteBuffers
#define glDeleteFramebuffers calibench_glDeleteFramebuffers
#define glDeleteProgram calibench_glDeleteProgram
#define glDeleteRenderbuffers calibench_glDeleteRenderbuffers
#define glDeleteShader calibench_glDeleteShader
#define glDeleteTextures calibench_glDeleteTextures
#define glDeleteVertexArrays calibench_glDeleteVertexArrays
#define glDepthFunc calibench_glDepthFunc
#define glDepthMask calibench_glDepthMask
#define glDetachShader calibench_glDetachShader
#define glDisable calibench_glDisable
#define glDisableVertexAttribArray calibench_glDisableVertexAttribArray
#define glDrawArrays calibench_glDrawArrays
#define glDrawElements calibench_glDrawElements
#define glDrawElementsBaseVertex calibench_glDrawElementsBaseVertex
#define glEnable calibench_glEnable
#define glEnableVertexAttribArray calibench_glEnableVertexAttribArray
#define glFinish calibench_glFinish
#define glFlush calibench_glFlush
#define glFramebufferRenderbuffer calibench_glFramebufferRenderbuffer
#define glFramebufferTexture2D calibench_glFramebufferTexture2D
#define glGenBuffers calibench_glGenBuffers
#define glGenFramebuffers calibench_glGenFramebuffers
#define glGenRenderbuffers calibench_glGenRenderbuffers
#define glGenTextures calibench_glGenTextures
#define glGenVertexArrays calibench_glGenVertexArrays
#define glGetAttribLocation calibench_glGetAttribLocation
#define glGetError calibench_glGetError
#define glGetFloatv calibench_glGetFloatv
#define glGetIntegerv calibench_glGetIntegerv
#define glGetProgramInfoLog calibench_glGetProgramInfoLog
#define glGetProgramiv calibench_glGetProgramiv
#define glGetShaderInfoLog calibench_glGetShaderInfoLog
#define glGetShaderiv calibench_glGetShaderiv
#define glGetString calibench_glGetString
#define glGetStringi calibench_glGetStringi
#define glGetUniformLocation calibench_glGetUniformLocation
#define glIsEnabled calibench_glIsEnabled
#define glLineWidth calibench_glLineWidth
#define glLinkProgram calibench_glLinkProgram
#define glPixelStorei calibench_glPixelStorei
#define glPolygonMode calibench_glPolygonMode
#define glReadBuffer calibench_glReadBuffer
#define glReadPixels calibench_glReadPixels
#define glRenderbufferStorage calibench_glRenderbufferStorage
#define glScissor calibench_glScissor
#define glShaderSource calibench_glShaderSource
#define glTexImage2D calibench_glTexImage2D
#define glTexParameteri calibench_glTexParameteri
#define glTexParameteriv calibench_glTexParameteriv
#define glTexSubImage2D calibench_glTexSubImage2D
#define glUniform1f calibench_glUniform1f
#define glUniform1i calibench_glUniform1i
#define glUniform2i calibench_glUniform2i
#define glUniform4f calibench_glUniform4f
#define glUniformMatrix4fv calibench_glUniformMatrix4fv
#define glUseProgram calibench_glUseProgram
#define glVertexAttribPointer calibench_glVertexAttribPointer
#define glViewport calibench_glViewport
// clang-format on

#define CALIBENCH_GL_DECLARE_POINTER(type, name) extern type name;
CALIBENCH_GL_FUNCTIONS(CALIBENCH_GL_DECLARE_POINTER)
#undef CALIBENCH_GL_DECLARE_POINTER
