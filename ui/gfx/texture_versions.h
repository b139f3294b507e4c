// Content versions of GL textures: every time a texture's pixels may change (a framebuffer bound
// for drawing, an image uploaded) it gets a new version from one process-wide counter. The window
// redraws only the parts of the screen that changed (ui/widgets/redraw_regions.h); a view that
// redraws its framebuffer leaves ImGui's draw data identical, so the version is what tells.
// GL thread only, like every GL call.
#pragma once

#include <cstdint>

namespace calibench::gfx {

// Gives `texture` a version no texture has had before.
void MarkTextureChanged(std::uint32_t texture);
// The texture's current version; 0 for a texture never marked.
std::uint64_t TextureVersion(std::uint32_t texture);

}  // namespace calibench::gfx
