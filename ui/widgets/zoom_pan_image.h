// The zoomable, pannable picture both workbenches show a camera (or depth) image in: fitted into
// the space left in the window, the wheel zooms about the pixel under the mouse (1x to 32x), a
// right drag pans. The owner draws the picture (a texture, or its own framebuffer already
// cropped) and its overlays where Placement says.
#pragma once

#include <imgui.h>

#include <cstdint>

#include "core/base/types.h"

namespace calibench::ui {

class ZoomPanImage {
 public:
  // Where the picture goes this frame: `size` screen pixels from `origin`, showing the part
  // [u0, u0 + span] x [v0, v0 + span] of the image (fractions of its width and height).
  struct Placement {
    ImVec2 origin, size;
    float u0 = 0, v0 = 0, span = 1;
    int image_width = 1, image_height = 1;
    // An image pixel (pixel centres at integers) on screen.
    ImVec2 ToScreen(const Vec2& pixel) const;
    // The same in normalized device coordinates of a framebuffer of `size` (y up), z = 0.
    Eigen::Vector3f ToNdc(const Vec2& pixel) const;
  };

  // Fits a image_width x image_height picture at the cursor into the space left in the window
  // (whole pixels, at least 1) and keeps the visible part inside the image.
  Placement Place(int image_width, int image_height);
  // Draws `texture` (the whole image) cropped to the visible part; the cursor moves below it.
  static void Show(const Placement& at, std::uint32_t texture);
  // Wheel and right drag; call when the picture is hovered. Takes effect the next frame.
  void HandleMouse(const Placement& at);
  // Changes whenever the zoom or the pan does (for the owner's redraw-when-changed keys).
  std::uint64_t Key() const;

 private:
  float zoom_ = 1.0f;                        // 1 = the whole image
  float center_x_ = 0.5f, center_y_ = 0.5f;  // visible centre, fractions of the image
};

}  // namespace calibench::ui
