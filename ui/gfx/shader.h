// Compiling and linking GLSL programs; requires a current context.
#pragma once

#include <cstdint>

namespace calibench::gfx {

// A linked vertex + fragment program (a GL name). The sources are embedded at build time
// (shader_sources.h), so a failure is a driver or programmer error, not bad input: it throws
// std::runtime_error naming `name` and carrying the compiler's log.
std::uint32_t BuildProgram(const char* name, const char* vertex_source,
                           const char* fragment_source);

}  // namespace calibench::gfx
