#include "ui/widgets/view_window.h"

namespace calibench::ui {
namespace {

constexpr ImGuiWindowFlags kPanelFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;
constexpr ImGuiWindowFlags kViewFlags =
    kPanelFlags | ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse;

bool BeginAt(const char* title, const Rect& r, ImGuiWindowFlags flags) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  return ImGui::Begin(title, nullptr, flags);
}

}  // namespace

bool BeginView(const char* title, const Rect& r) { return BeginAt(title, r, kViewFlags); }

bool BeginPanel(const char* title, const Rect& r) { return BeginAt(title, r, kPanelFlags); }

ImTextureID TextureId(std::uint32_t texture) {
  return reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture));
}

void FramebufferImage(const gfx::Framebuffer& framebuffer, ImVec2 size) {
  ImGui::Image(TextureId(framebuffer.color_texture()), size, ImVec2(0, 1), ImVec2(1, 0));
}

}  // namespace calibench::ui
