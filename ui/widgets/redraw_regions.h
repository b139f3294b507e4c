// Redrawing only what changed. ImGui rebuilds its whole draw data every frame; drawing all of it
// costs a software rasteriser (llvmpipe, the laptop without a GPU, CI) about 12 ms at 1600 x 900
// whatever changed, because every pixel is shaded again. The window keeps its last frame in an
// offscreen framebuffer, so a frame only needs to repaint the pixels whose draw commands differ
// from the last frame's: RedrawRegions finds them (a fingerprint of each command: its vertices,
// indices, clip rectangle, texture and the texture's content version), and RegionRedraw turns the
// draw data into one draw list whose commands are clipped to those regions. Inside a region
// everything is drawn again in the original order, so the result is the full frame's, pixel for
// pixel (tests/ui/widgets/test_redraw_regions.cpp).
#pragma once

#include <imgui.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace calibench::ui {

// Pixels of the framebuffer as glScissor takes them: from the lower-left corner, x right, y up.
struct PixelBox {
  int x = 0, y = 0, width = 0, height = 0;
  long long Area() const { return static_cast<long long>(width) * height; }
  bool operator==(const PixelBox&) const = default;
};

// The pixels ImGui's OpenGL3 backend lets `command` touch (its scissor box), within the
// framebuffer of `draw_data`; width or height 0 when none.
PixelBox CommandScissor(const ImDrawData& draw_data, const ImDrawCmd& command);
// The framebuffer of `draw_data` as the backend computes it (display size x framebuffer scale).
PixelBox WholeFramebuffer(const ImDrawData& draw_data);

class RedrawRegions {
 public:
  // The content version of a texture an ImGui command samples (gfx::TextureVersion).
  using TextureVersionFn = std::function<std::uint64_t(ImTextureID)>;
  explicit RedrawRegions(TextureVersionFn texture_version);

  // The disjoint boxes to repaint so that the framebuffer, which holds the last frame passed here
  // (unless Forget() was called since), shows `draw_data`: none when nothing changed, the whole
  // framebuffer on the first frame.
  std::vector<PixelBox> Update(const ImDrawData& draw_data);
  // The framebuffer no longer holds the last frame (new, resized, drawn into by someone else):
  // the next Update repaints everything.
  void Forget() { have_previous_ = false; }

 private:
  struct CommandPrint {
    std::uint64_t hash = 0;
    PixelBox box;
  };
  struct ListPrint {
    std::uint64_t name = 0;  // the owner window's name, hashed
    PixelBox bounds;
    std::vector<CommandPrint> commands;
  };
  std::vector<ListPrint> Print(const ImDrawData& draw_data) const;
  std::vector<PixelBox> Changed(const std::vector<ListPrint>& current) const;

  TextureVersionFn texture_version_;
  std::vector<ListPrint> previous_;
  PixelBox previous_framebuffer_;
  bool have_previous_ = false;
};

// The draw data repainting only some regions: every command clipped to each region (disjoint), in
// the original order within a region, gathered in one draw list. Needs a renderer that honours
// ImDrawCmd::VtxOffset (ImGuiBackendFlags_RendererHasVtxOffset); create with an ImGui context.
class RegionRedraw {
 public:
  RegionRedraw();
  RegionRedraw(const RegionRedraw&) = delete;
  RegionRedraw& operator=(const RegionRedraw&) = delete;
  // What to render to repaint `regions` of draw_data's framebuffer; nullptr when the draw data
  // holds user callbacks (render it whole instead). Valid until the next call.
  const ImDrawData* Compose(const ImDrawData& draw_data, const std::vector<PixelBox>& regions);

 private:
  ImDrawList composed_;
  ImDrawList* composed_list_ = &composed_;
  ImDrawData composed_data_;
};

}  // namespace calibench::ui
