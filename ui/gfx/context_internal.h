// The headless backends behind CreateHeadlessContext, one translation unit each (OSMesa's header
// pulls in <GL/gl.h>, which must not meet gl_api.h).
#pragma once

#include <memory>
#include <string>

#include "ui/gfx/context.h"

namespace calibench::gfx::internal {

// What the EGL and OSMesa contexts share. MakeCurrent throws what TryMakeCurrent says: a context
// that worked once and then cannot be made current is a broken driver, not bad input.
class HeadlessContext : public GlContext {
 public:
  // Makes the context current and loads GL; false with *why.
  virtual bool TryMakeCurrent(std::string* why) = 0;
  void MakeCurrent() final;
  std::string Description() const final { return description_; }
  // Makes a new context current for the first time and describes it ("<label>: <GL summary>");
  // nullptr with *why ("<label>: reason") when it cannot be made current.
  static std::unique_ptr<GlContext> Activate(std::unique_ptr<HeadlessContext> context,
                                             const std::string& label, std::string* why);

 private:
  std::string description_;
};

// EGL without a surface: Mesa's surfaceless platform, else the first EGL device (NVIDIA's EGL
// exposes its GPUs this way). GL 3.3+ core, loaded and current; nullptr with *why otherwise.
std::unique_ptr<GlContext> CreateEglContext(std::string* why);

// OSMesa (Mesa's software rasterizer into client memory), GL 3.3+ core, loaded and current.
std::unique_ptr<GlContext> CreateOsMesaContext(std::string* why);

}  // namespace calibench::gfx::internal
