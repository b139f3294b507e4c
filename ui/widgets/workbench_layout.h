// The layouts both workbenches offer: the whole workbench (three views side by side on top, the
// measurements list and the solver panel below, a status line at the bottom) or one of its three
// views filling the display. A workbench's layout enum lists them in that order.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "ui/widgets/view_window.h"

namespace calibench::ui {

// The layouts' names in the order of a workbench's layout enum: the whole workbench, then each
// view alone, left to right (e.g. "workbench", "lidar", "camera", "3d").
using LayoutNames = std::vector<const char*>;

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

// The layout number of the guide arrangement (after the whole workbench, 0, and the three views
// alone, 1 to 3): camera and 3D views over the solver panel, what `render --view guide` draws.
constexpr int kGuideLayout = 4;

// Where each part of one frame goes, screen pixels.
struct FrameRects {
  std::array<Rect, 3> views;  // left to right
  int alone = -1;             // the view shown alone, -1: the whole workbench
  Rect measurements, solver, status;
  // The guide (kGuideLayout): the second and third views side by side over the solver panel.
  bool guide = false;
  bool Shows(int view) const { return guide ? view > 0 : alone < 0 || alone == view; }
  bool panels() const { return alone < 0; }  // the panels, the status line and the keys
  bool measurements_shown() const { return alone < 0 && !guide; }
};

// A workbench's proportions: the views' share of the height (above the panels) and the
// measurements list's share of the width (beside the solver panel).
struct LayoutShares {
  float views_height = 0.58f;
  float measurements_width = 0.45f;
};
// The shares of `workbench` ("lidar_camera" or "lrf") in assets/workbench/layout.json (found
// beside the binary, core/io/assets.h); `defaults` where the file or the entry is missing (said
// once on stderr). Throws IoError naming the file when it is malformed or a share is outside
// [0.2, 0.8].
LayoutShares LoadLayoutShares(const std::string& workbench, const LayoutShares& defaults);

// The frame of a layout (its enum value) on a width x height display.
FrameRects ArrangeFrame(int layout, int width, int height, const LayoutShares& shares);
// The same below a strip of `top` pixels (the window's menu bar).
FrameRects ArrangeFrame(int layout, int width, int height, const LayoutShares& shares, float top);

}  // namespace calibench::ui
