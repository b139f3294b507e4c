// OSMesa: Mesa rendering into client memory, the headless fallback where EGL has no driver.
// This file must not include gl_api.h: <GL/osmesa.h> brings <GL/gl.h> with real glFoo prototypes.
// It makes no GL call of its own; everything goes through LoadGl.
#include <GL/osmesa.h>

#include <array>

#include "ui/gfx/context_internal.h"
#include "ui/gfx/gl_loader.h"

namespace calibench::gfx::internal {
namespace {

void* OsMesaProc(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }

class OsMesaGlContext final : public HeadlessContext {
 public:
  explicit OsMesaGlContext(OSMesaContext context) : context_(context) {}
  ~OsMesaGlContext() override { OSMesaDestroyContext(context_); }

  bool TryMakeCurrent(std::string* why) override {
    // OSMesa always needs a colour buffer to be current; we never draw into it (views render
    // into gfx::Framebuffer objects), so a tiny one does.
    if (!OSMesaMakeCurrent(context_, dummy_buffer_.data(), GL_UNSIGNED_BYTE, kDummySize,
                           kDummySize)) {
      *why = "OSMesaMakeCurrent failed";
      return false;
    }
    return LoadGl(OsMesaProc, why);
  }

 private:
  static constexpr int kDummySize = 4;  // pixels
  OSMesaContext context_;
  std::array<unsigned char, kDummySize * kDummySize * 4> dummy_buffer_{};  // RGBA8
};

}  // namespace

std::unique_ptr<GlContext> CreateOsMesaContext(std::string* why) {
  // No depth/stencil in the dummy buffer: framebuffers bring their own depth attachment.
  // clang-format off
  const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA,
                            OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0, OSMESA_ACCUM_BITS, 0,
                            OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3,
                            0};
  // clang-format on
  OSMesaContext context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (context == nullptr) {
    *why = "OSMesa: OSMesaCreateContextAttribs gave no GL 3.3 core context";
    return nullptr;
  }
  return HeadlessContext::Activate(std::make_unique<OsMesaGlContext>(context), "OSMesa", why);
}

}  // namespace calibench::gfx::internal
