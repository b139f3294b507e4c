#include "ui/gfx/shader.h"

#include <optional>
#include <stdexcept>
#include <string>

#include "ui/gfx/gl_api.h"

namespace calibench::gfx {
namespace {

// The info log of a shader (glGetShaderiv, glGetShaderInfoLog; status GL_COMPILE_STATUS) or a
// program (the glGetProgram pair; GL_LINK_STATUS) when its status is not GL_TRUE: the compiler's
// or the linker's messages. nullopt when the status is GL_TRUE.
std::optional<std::string> FailureLog(GLuint object, GLenum status,
                                      PFNGLGETSHADERIVPROC get_parameter,
                                      PFNGLGETSHADERINFOLOGPROC get_log) {
  GLint ok = GL_FALSE;
  get_parameter(object, status, &ok);
  if (ok == GL_TRUE) return std::nullopt;
  GLint length = 0;
  get_parameter(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(length > 0 ? length : 1), '\0');
  get_log(object, length, nullptr, log.data());
  return std::string(log.c_str());
}

GLuint Compile(const char* name, GLenum stage, const char* source) {
  const GLuint shader = glCreateShader(stage);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  if (const auto log = FailureLog(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog)) {
    glDeleteShader(shader);
    throw std::runtime_error(std::string("GLSL ") +
                             (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader of '" +
                             name + "' does not compile: " + *log);
  }
  return shader;
}

}  // namespace

std::uint32_t BuildProgram(const char* name, const char* vertex_source,
                           const char* fragment_source) {
  const GLuint vertex = Compile(name, GL_VERTEX_SHADER, vertex_source);
  GLuint fragment = 0;
  try {
    fragment = Compile(name, GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex);
  glAttachShader(program, fragment);
  glLinkProgram(program);
  // The program keeps the compiled code; the shader objects are no longer needed.
  glDetachShader(program, vertex);
  glDetachShader(program, fragment);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  if (const auto log = FailureLog(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog)) {
    glDeleteProgram(program);
    throw std::runtime_error(std::string("GLSL program '") + name + "' does not link: " + *log);
  }
  return program;
}

}  // namespace calibench::gfx
