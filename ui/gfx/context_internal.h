// The headless backends behind CreateHeadlessContext, one translation unit each (OSMesa's header
// pulls in <GL/gl.h>, which must not meet gl_api.h).
#pragma once

#include <memory>
#include <string>

#include "ui/gfx/context.h"

namespace calibench::gfx::internal {

// EGL without a surface: Mesa's surfaceless platform, else the first EGL device (NVIDIA's EGL
// exposes its GPUs this way). GL 3.3+ core, loaded and current; nullptr with *why otherwise.
std::unique_ptr<GlContext> CreateEglContext(std::string* why);

// OSMesa (Mesa's software rasterizer into client memory), GL 3.3+ core, loaded and current.
std::unique_ptr<GlContext> CreateOsMesaContext(std::string* why);

}  // namespace calibench::gfx::internal
