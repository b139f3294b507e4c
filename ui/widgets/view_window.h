// The fixed windows a workbench frame is made of: views (no scrolling, the mouse belongs to the
// picture) and panels (scrolling), each placed at a rectangle of the display, and the pictures
// they show from GL textures.
#pragma once

#include <imgui.h>

#include <cstdint>

#include "ui/gfx/framebuffer.h"

namespace calibench::ui {

// A rectangle of the display, screen pixels from the top-left corner.
struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
};

// ImGui::Begin of a view at `r`: not movable, resizable or scrollable. Call ImGui::End() whatever
// it returns.
bool BeginView(const char* title, const Rect& r);
// The same for a panel below the views, which scrolls.
bool BeginPanel(const char* title, const Rect& r);

// A GL texture name as ImGui's texture id.
ImTextureID TextureId(std::uint32_t texture);
// The framebuffer's colour texture upright (GL stores it bottom row first), `size` pixels.
void FramebufferImage(const gfx::Framebuffer& framebuffer, ImVec2 size);

}  // namespace calibench::ui
