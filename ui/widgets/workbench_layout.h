// The layouts both workbenches offer: the whole workbench (three views side by side on top, the
// measurements list and the solver panel below, a status line at the bottom) or one of its three
// views filling the display. A workbench's layout enum lists them in that order.
#pragma once

#include <array>
#include <string>

#include "ui/widgets/view_window.h"

namespace calibench::ui {

// The layouts' names in the order of a workbench's layout enum: the whole workbench, then each
// view alone, left to right (e.g. "workbench", "lidar", "camera", "3d").
using LayoutNames = std::array<const char*, 4>;

// Sets *layout to the enum value named `name`; false (and *layout untouched) for other names.
template <typename Layout>
bool ParseLayoutName(const std::string& name, const LayoutNames& names, Layout* layout) {
  for (size_t i = 0; i < names.size(); ++i)
    if (name == names[i]) {
      *layout = static_cast<Layout>(i);
      return true;
    }
  return false;
}

// Where each part of one frame goes, screen pixels.
struct FrameRects {
  std::array<Rect, 3> views;  // left to right
  int alone = -1;             // the view shown alone, -1: the whole workbench
  Rect measurements, solver, status;
  bool Shows(int view) const { return alone < 0 || alone == view; }
  bool panels() const { return alone < 0; }  // the panels, the status line and the keys
};

// The frame of a layout (its enum value) on a width x height display; the measurements list takes
// measurements_share of the width.
FrameRects ArrangeFrame(int layout, int width, int height, float measurements_share);
// The same below a strip of `top` pixels (the window's menu bar).
FrameRects ArrangeFrame(int layout, int width, int height, float measurements_share, float top);

}  // namespace calibench::ui
