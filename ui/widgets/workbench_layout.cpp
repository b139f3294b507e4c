#include "ui/widgets/workbench_layout.h"

#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/base/types.h"
#include "core/io/assets.h"

namespace calibench::ui {

LayoutShares LoadLayoutShares(const std::string& workbench, const LayoutShares& defaults) {
  std::filesystem::path path;
  try {
    path = FindAsset("workbench/layout.json");
  } catch (const IoError& e) {
    static std::once_flag said;
    std::call_once(said,
                   [&] { std::fprintf(stderr, "%s: the built-in layout is used\n", e.what()); });
    return defaults;
  }
  std::ifstream in(path);
  const auto json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    throw IoError(path.string() + ": not a JSON object");
  if (!json.contains(workbench)) return defaults;
  LayoutShares shares = defaults;
  auto share = [&](const char* key, float* value) {
    const auto& entry = json[workbench];
    if (!entry.contains(key)) return;
    if (!entry[key].is_number() || entry[key].get<double>() < 0.2 || entry[key].get<double>() > 0.8)
      throw IoError(path.string() + ": " + workbench + "." + key +
                    " must be a number in [0.2, 0.8]");
    *value = entry[key].get<float>();
  };
  share("views_height_share", &shares.views_height);
  share("measurements_width_share", &shares.measurements_width);
  return shares;
}

FrameRects ArrangeFrame(int layout, int width, int height, const LayoutShares& shares, float top) {
  FrameRects frame = ArrangeFrame(layout, width, static_cast<int>(height - top), shares);
  for (Rect* r : {&frame.views[0], &frame.views[1], &frame.views[2], &frame.measurements,
                  &frame.solver, &frame.status})
    r->y += top;
  return frame;
}

FrameRects ArrangeFrame(int layout, int width, int height, const LayoutShares& shares) {
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  FrameRects frame;
  if (layout == kGuideLayout) {
    const float status_h = ImGui::GetFrameHeightWithSpacing() + 8;
    const float top_h = std::floor((h - status_h) * 0.62f), half = std::floor(w / 2);
    frame.guide = true;
    frame.views = {Rect{0, 0, 0, 0}, Rect{0, 0, half, top_h}, Rect{half, 0, w - half, top_h}};
    frame.solver = {0, top_h, w, h - status_h - top_h};
    frame.status = {0, h - status_h, w, status_h};
    return frame;
  }
  if (layout > 0) {
    frame.alone = layout - 1;
    frame.views[frame.alone] = {0, 0, w, h};
    return frame;
  }
  const float status_h = ImGui::GetFrameHeightWithSpacing() + 8;
  const float top_h = std::floor((h - status_h) * shares.views_height);
  const float third = std::floor(w / 3);
  frame.views = {Rect{0, 0, third, top_h}, Rect{third, 0, third, top_h},
                 Rect{2 * third, 0, w - 2 * third, top_h}};
  const float bottom_h = h - status_h - top_h, left_w = std::floor(w * shares.measurements_width);
  frame.measurements = {0, top_h, left_w, bottom_h};
  frame.solver = {left_w, top_h, w - left_w, bottom_h};
  frame.status = {0, h - status_h, w, status_h};
  return frame;
}

}  // namespace calibench::ui
