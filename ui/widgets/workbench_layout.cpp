#include "ui/widgets/workbench_layout.h"

#include <imgui.h>

#include <cmath>

namespace calibench::ui {

FrameRects ArrangeFrame(int layout, int width, int height, float measurements_share, float top) {
  FrameRects frame =
      ArrangeFrame(layout, width, static_cast<int>(height - top), measurements_share);
  for (Rect* r : {&frame.views[0], &frame.views[1], &frame.views[2], &frame.measurements,
                  &frame.solver, &frame.status})
    r->y += top;
  return frame;
}

FrameRects ArrangeFrame(int layout, int width, int height, float measurements_share) {
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  FrameRects frame;
  if (layout > 0) {
    frame.alone = layout - 1;
    frame.views[frame.alone] = {0, 0, w, h};
    return frame;
  }
  const float status_h = ImGui::GetFrameHeightWithSpacing() + 8;
  const float top_h = std::floor((h - status_h) * 0.58f);
  const float third = std::floor(w / 3);
  frame.views = {Rect{0, 0, third, top_h}, Rect{third, 0, third, top_h},
                 Rect{2 * third, 0, w - 2 * third, top_h}};
  const float bottom_h = h - status_h - top_h, left_w = std::floor(w * measurements_share);
  frame.measurements = {0, top_h, left_w, bottom_h};
  frame.solver = {left_w, top_h, w - left_w, bottom_h};
  frame.status = {0, h - status_h, w, status_h};
  return frame;
}

}  // namespace calibench::ui
