// OSMesa: Mesa rendering into client memory, the headless fallback where EGL has no driver.
// This file must not include gl_api.h: <GL/osmesa.h> brings <GL/gl.h> with real glFoo prototypes.
// It makes no GL call of its own; everything goes through LoadGl.
//
// libOSMesa is opened with dlopen when a context is first asked for, not linked: it brings
// libLLVM, whose loading cost every calibench command 60 ms at start-up (`calibench --help` took
// 0.30 s), though only a headless render without EGL ever uses it.
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <array>
#include <string>
#include <type_traits>

#include "ui/gfx/context_internal.h"
#include "ui/gfx/gl_loader.h"

namespace calibench::gfx::internal {
namespace {

// The four OSMesa entry points this file uses, from the library opened at run time.
struct OsMesaApi {
  decltype(&OSMesaCreateContextAttribs) create_context_attribs = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  std::string failure;  // why the library or a symbol is missing; empty when loaded
};

const OsMesaApi& OsMesa() {
  static const OsMesaApi api = [] {
    OsMesaApi loaded;
    void* library = nullptr;
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"})
      if ((library = dlopen(name, RTLD_NOW | RTLD_LOCAL)) != nullptr) break;
    if (library == nullptr) {
      const char* error = dlerror();
      loaded.failure = std::string("cannot load libOSMesa.so.8 (") + (error ? error : "?") +
                       "; apt-get install libosmesa6)";
      return loaded;
    }
    auto symbol = [&](auto* function, const char* name) {
      *function = reinterpret_cast<std::remove_pointer_t<decltype(function)>>(dlsym(library, name));
      if (*function == nullptr && loaded.failure.empty())
        loaded.failure = std::string("libOSMesa has no ") + name;
    };
    symbol(&loaded.create_context_attribs, "OSMesaCreateContextAttribs");
    symbol(&loaded.make_current, "OSMesaMakeCurrent");
    symbol(&loaded.get_proc_address, "OSMesaGetProcAddress");
    symbol(&loaded.destroy_context, "OSMesaDestroyContext");
    return loaded;  // the library stays open for the process's life
  }();
  return api;
}

void* OsMesaProc(const char* name) {
  return reinterpret_cast<void*>(OsMesa().get_proc_address(name));
}

class OsMesaGlContext final : public HeadlessContext {
 public:
  explicit OsMesaGlContext(OSMesaContext context) : context_(context) {}
  ~OsMesaGlContext() override { OsMesa().destroy_context(context_); }

  bool TryMakeCurrent(std::string* why) override {
    // OSMesa always needs a colour buffer to be current; we never draw into it (views render
    // into gfx::Framebuffer objects), so a tiny one does.
    if (!OsMesa().make_current(context_, dummy_buffer_.data(), GL_UNSIGNED_BYTE, kDummySize,
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
  if (!OsMesa().failure.empty()) {
    *why = "OSMesa: " + OsMesa().failure;
    return nullptr;
  }
  // No depth/stencil in the dummy buffer: framebuffers bring their own depth attachment.
  // clang-format off
  const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA,
                            OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0, OSMESA_ACCUM_BITS, 0,
                            OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3,
                            0};
  // clang-format on
  OSMesaContext context = OsMesa().create_context_attribs(attributes, nullptr);
  if (context == nullptr) {
    *why = "OSMesa: OSMesaCreateContextAttribs gave no GL 3.3 core context";
    return nullptr;
  }
  return HeadlessContext::Activate(std::make_unique<OsMesaGlContext>(context), "OSMesa", why);
}

}  // namespace calibench::gfx::internal
