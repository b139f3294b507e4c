// What the LRF workbench's views share: the faces' colours, the selected pair's view frame, the
// target's scan points and the corner rings (definitions in workbench.cpp; the scan view is
// workbench_scan.cpp, the panels workbench_panels.cpp).
#pragma once

#include <imgui.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "ui/lrf/controller.h"
#include "ui/widgets/workbench_layout.h"

namespace calibench::ui::lrf_view {

// Faces 0 (base), 1 (ABC), 2 (ACD): the same colours in every view. RGB.
inline constexpr std::uint8_t kFaceRgb[3][3] = {{80, 150, 255}, {240, 90, 200}, {70, 215, 120}};
inline constexpr const char* kFaceNames[3] = {"base", "ABC", "ACD"};
inline const ImU32 kScanInCamera =
    IM_COL32(255, 225, 40, 255);  // scan points moved into the camera
inline const ImU32 kBoardColor = IM_COL32(255, 150, 40, 255);

inline ImU32 FaceColor(int face, int alpha = 255) {
  return IM_COL32(kFaceRgb[face][0], kFaceRgb[face][1], kFaceRgb[face][2], alpha);
}
inline ImVec4 FaceColorVec(int face) {
  return {kFaceRgb[face][0] / 255.f, kFaceRgb[face][1] / 255.f, kFaceRgb[face][2] / 255.f, 1};
}

// The selected pair's features, or nullptr.
const LrfPairFeatures* SelectedFeatures(const LrfSnapshot& s);
// Begins a view of the selected pair: its features, or nullptr after saying what the view waits
// for. Call ImGui::End() either way.
const LrfPairFeatures* BeginPairView(const char* title, const LrfSnapshot& s, const Rect& r);
// Scan points on the target, with their face (0..2; 3 = checkerboard).
std::vector<std::pair<Vec2, int>> TargetPoints(const LrfPairFeatures& pair);

// Corner `c` (0..2: F, G, H) of the three-face target as a white ring with its name.
inline void DrawCornerRing(ImDrawList* draw, ImVec2 q, int c) {
  constexpr const char* kCorners[3] = {"F", "G", "H"};
  draw->AddCircle(q, 6.0f, IM_COL32(255, 255, 255, 255), 16, 2.0f);
  draw->AddText({q.x + 8, q.y - 8}, IM_COL32(255, 255, 255, 255), kCorners[c]);
}

}  // namespace calibench::ui::lrf_view
