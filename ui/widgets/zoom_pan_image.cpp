#include "ui/widgets/zoom_pan_image.h"

#include <algorithm>
#include <cmath>

#include "ui/widgets/view_window.h"

namespace calibench::ui {

ImVec2 ZoomPanImage::Placement::ToScreen(const Vec2& pixel) const {
  return ImVec2(
      origin.x + static_cast<float>(((pixel.x() + 0.5) / image_width - u0) / span * size.x),
      origin.y + static_cast<float>(((pixel.y() + 0.5) / image_height - v0) / span * size.y));
}

Eigen::Vector3f ZoomPanImage::Placement::ToNdc(const Vec2& pixel) const {
  return Eigen::Vector3f(static_cast<float>(((pixel.x() + 0.5) / image_width - u0) / span * 2 - 1),
                         static_cast<float>(1 - ((pixel.y() + 0.5) / image_height - v0) / span * 2),
                         0.0f);
}

ZoomPanImage::Placement ZoomPanImage::Place(int image_width, int image_height) {
  Placement at;
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float fit = std::min(avail.x / image_width, avail.y / image_height);
  at.size = ImVec2(std::max(1.0f, std::floor(image_width * fit)),
                   std::max(1.0f, std::floor(image_height * fit)));
  at.origin = ImGui::GetCursorScreenPos();
  at.image_width = image_width;
  at.image_height = image_height;
  // The visible part is [u0, u0 + span] x [v0, v0 + span] (fractions of the image).
  at.span = 1.0f / zoom_;
  center_x_ = std::clamp(center_x_, at.span / 2, 1 - at.span / 2);
  center_y_ = std::clamp(center_y_, at.span / 2, 1 - at.span / 2);
  at.u0 = center_x_ - at.span / 2;
  at.v0 = center_y_ - at.span / 2;
  return at;
}

void ZoomPanImage::Show(const Placement& at, std::uint32_t texture) {
  ImGui::Image(TextureId(texture), at.size, ImVec2(at.u0, at.v0),
               ImVec2(at.u0 + at.span, at.v0 + at.span));
}

void ZoomPanImage::HandleMouse(const Placement& at) {
  const ImGuiIO& io = ImGui::GetIO();
  const float x = (io.MousePos.x - at.origin.x) / at.size.x;  // fractions of the picture
  const float y = (io.MousePos.y - at.origin.y) / at.size.y;
  if (io.MouseWheel != 0) {
    // Zoom about the pixel under the mouse: it stays where it is on screen.
    const float mx = at.u0 + x * at.span, my = at.v0 + y * at.span;
    zoom_ = std::clamp(zoom_ * std::pow(1.25f, io.MouseWheel), 1.0f, 32.0f);
    const float new_span = 1.0f / zoom_;
    center_x_ = mx - x * new_span + new_span / 2;
    center_y_ = my - y * new_span + new_span / 2;
  }
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
    center_x_ -= io.MouseDelta.x / at.size.x * at.span;
    center_y_ -= io.MouseDelta.y / at.size.y * at.span;
  }
}

std::uint64_t ZoomPanImage::Key() const {
  return static_cast<std::uint64_t>(zoom_ * 1e4) * 15485863 ^
         static_cast<std::uint64_t>(center_x_ * 1e6) * 32452843 ^
         static_cast<std::uint64_t>(center_y_ * 1e6) * 49979687;
}

}  // namespace calibench::ui
