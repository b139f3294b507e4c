// The LRF workbench's scan view: the LRF frame seen from above (screen right = LRF -y, screen
// up = LRF +x), the scan's points by face, the fitted lines, both sensors and the readouts.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geometry/geometry.h"
#include "ui/lrf/workbench.h"
#include "ui/lrf/workbench_draw.h"

namespace calibench::ui {
namespace {

using namespace lrf_view;

// ---- The scan view: the LRF frame seen from above, screen right = LRF -y, screen up = LRF +x.

struct ScanCanvas {
  ImVec2 origin, size;  // screen pixels
  Vec2 center;          // the LRF-frame point at the canvas's centre, metres
  double scale = 1;     // pixels per metre

  ImVec2 end() const { return ImVec2(origin.x + size.x, origin.y + size.y); }
  ImVec2 ToScreen(const Vec2& p) const {
    const ImVec2 mid(origin.x + size.x / 2, origin.y + size.y / 2);
    return ImVec2(mid.x - static_cast<float>((p.y() - center.y()) * scale),
                  mid.y - static_cast<float>((p.x() - center.x()) * scale));
  }
  bool Inside(const ImVec2& q) const {
    return q.x >= origin.x && q.x <= end().x && q.y >= origin.y && q.y <= end().y;
  }
};

// Fits the LRF origin and the target (margin 0.3 m and a fifth of their extent); `zoom` about the
// target's centre.
ScanCanvas FitScanCanvas(ImVec2 origin, ImVec2 size,
                         const std::vector<std::pair<Vec2, int>>& target, float zoom) {
  Vec2 lo(0, 0), hi(0, 0), target_center(1, 0);
  if (!target.empty()) {
    target_center.setZero();
    for (const auto& [p, face] : target) {
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      target_center += p / static_cast<double>(target.size());
    }
  } else {
    lo = Vec2(-1, -1), hi = Vec2(1, 1);
  }
  const Vec2 margin = Vec2::Constant(0.3) + 0.2 * (hi - lo);
  lo -= margin, hi += margin;
  const double fit = std::min(size.x / (hi.y() - lo.y()), size.y / (hi.x() - lo.x()));
  ScanCanvas canvas{origin, size, target_center + ((lo + hi) / 2 - target_center) / zoom};
  canvas.scale = fit * zoom;
  return canvas;
}

// Metre grid lines labelled with their x and y: the smallest of 0.1 / 0.2 / 0.5 / 1 / 2 / 5 m at
// least 45 px apart.
void DrawScanGrid(ImDrawList* draw, const ScanCanvas& canvas) {
  double spacing = 5.0;
  for (double candidate : {0.1, 0.2, 0.5, 1.0, 2.0, 5.0})
    if (candidate * canvas.scale >= 45) {
      spacing = candidate;
      break;
    }
  const ImVec2 origin = canvas.origin, end = canvas.end();
  const double half_x = canvas.size.y / 2 / canvas.scale, half_y = canvas.size.x / 2 / canvas.scale;
  auto line_color = [](int k) {
    return k == 0 ? IM_COL32(95, 95, 105, 255) : IM_COL32(50, 50, 58, 255);
  };
  char label[32];
  for (int k = static_cast<int>(std::floor((canvas.center.x() - half_x) / spacing));
       k * spacing <= canvas.center.x() + half_x; ++k) {
    const float y = canvas.ToScreen(Vec2(k * spacing, 0)).y;
    draw->AddLine({origin.x, y}, {end.x, y}, line_color(k));
    std::snprintf(label, sizeof(label), "x %g m", k * spacing);
    draw->AddText({origin.x + 3, y - 15}, IM_COL32(120, 120, 130, 255), label);
  }
  for (int k = static_cast<int>(std::floor((canvas.center.y() - half_y) / spacing));
       k * spacing <= canvas.center.y() + half_y; ++k) {
    const float x = canvas.ToScreen(Vec2(0, k * spacing)).x;
    draw->AddLine({x, origin.y}, {x, end.y}, line_color(k));
    std::snprintf(label, sizeof(label), "y %g", k * spacing);
    draw->AddText({x + 3, end.y - 16}, IM_COL32(120, 120, 130, 255), label);
  }
}

// A fitted line as a segment over its points' extent (plus 5 cm).
void DrawFittedLine(ImDrawList* draw, const ScanCanvas& canvas, const Line2& line,
                    const std::vector<Vec2>& points, ImU32 color) {
  if (points.empty()) return;
  const Vec2 direction(-line.normal.y(), line.normal.x());
  const Vec2 foot = -line.normal * line.offset;
  double t0 = 1e9, t1 = -1e9;
  for (const Vec2& p : points)
    t0 = std::min(t0, (p - foot).dot(direction)), t1 = std::max(t1, (p - foot).dot(direction));
  draw->AddLine(canvas.ToScreen(foot + (t0 - 0.05) * direction),
                canvas.ToScreen(foot + (t1 + 0.05) * direction), color, 1.5f);
}

// Every return in grey, the target's points coloured by face, the fitted lines and corners.
void DrawScanPoints(ImDrawList* draw, const ScanCanvas& canvas, const LrfPairFeatures& pair,
                    const std::vector<std::pair<Vec2, int>>& target) {
  const LaserScan& scan = pair.scan;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.Valid(i)) continue;
    const ImVec2 q = canvas.ToScreen(scan.Point(i));
    if (canvas.Inside(q))
      draw->AddRectFilled({q.x - 1, q.y - 1}, {q.x + 1, q.y + 1}, IM_COL32(150, 150, 158, 255));
  }
  for (const auto& [p, face] : target)
    draw->AddCircleFilled(canvas.ToScreen(p), 2.5f, face < 3 ? FaceColor(face) : kBoardColor, 8);
  if (pair.three_face && pair.three_face->scan.ok) {
    const ScanFeatures& features = pair.three_face->scan;
    for (int face = 0; face < 3; ++face)
      DrawFittedLine(draw, canvas, features.lines[face], features.face_points[face],
                     FaceColor(face, 200));
    for (int c = 0; c < 3; ++c) DrawCornerRing(draw, canvas.ToScreen(features.corners[c]), c);
  }
  if (pair.board_scan && pair.board_scan->ok)
    DrawFittedLine(draw, canvas, pair.board_scan->line, pair.board_scan->points, kBoardColor);
}

// The LRF's axes (x forward: red, up the screen; y left: green) and, with an estimate, the
// camera's centre and optical axis seen from above.
void DrawScanSensors(ImDrawList* draw, const ScanCanvas& canvas, const Pose* estimate) {
  const ImVec2 o = canvas.ToScreen(Vec2::Zero());
  draw->AddLine(o, {o.x, o.y - 40}, IM_COL32(255, 70, 70, 255), 2.0f);
  draw->AddLine(o, {o.x - 40, o.y}, IM_COL32(70, 230, 70, 255), 2.0f);
  draw->AddCircleFilled(o, 4.0f, IM_COL32(235, 235, 235, 255), 12);
  draw->AddText({o.x + 6, o.y + 2}, IM_COL32(235, 235, 235, 255), "LRF");
  if (!estimate) return;
  const Pose lrf_from_cam = estimate->inverse();
  const Vec3 c = lrf_from_cam.translation(), axis = lrf_from_cam.linear().col(2);
  const ImVec2 q = canvas.ToScreen(c.head<2>());
  draw->AddLine(q, canvas.ToScreen(c.head<2>() + 0.3 * axis.head<2>()), IM_COL32(80, 220, 255, 255),
                2.0f);
  draw->AddCircleFilled(q, 4.0f, IM_COL32(80, 220, 255, 255), 12);
  draw->AddText({q.x + 6, q.y - 16}, IM_COL32(80, 220, 255, 255), "camera");
}

// Rays, target points and line RMS (or why there is no target); the face colours.
void ScanReadouts(const LrfPairFeatures& pair, size_t target_points) {
  const size_t rays = pair.scan.ranges.size();
  if (pair.three_face && pair.three_face->scan.ok) {
    ImGui::Text("%zu rays, %zu on the target, line RMS %.1f mm", rays, target_points,
                pair.three_face->scan.rms_m * 1e3);
  } else if (pair.board_scan && pair.board_scan->ok) {
    ImGui::Text("%zu rays, %zu on the board, line RMS %.1f mm", rays, target_points,
                pair.board_scan->rms_m * 1e3);
  } else {
    const std::string why = pair.three_face   ? pair.three_face->scan.reason
                            : pair.board_scan ? pair.board_scan->reason
                                              : pair.reason;
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no target: %s", why.c_str());
  }
  for (int face = 0; face < 3 && pair.three_face; ++face) {
    ImGui::TextColored(FaceColorVec(face), "%s", kFaceNames[face]);
    ImGui::SameLine();
  }
  ImGui::TextDisabled("rings: F G H   wheel: zoom about the target");
}

}  // namespace

void LrfWorkbench::ScanView(const LrfSnapshot& s, const Rect& r) {
  const LrfPairFeatures* pair = BeginPairView("Scan (LRF frame, top-down)", s, r);
  if (!pair) return ImGui::End();
  const auto target = TargetPoints(*pair);
  ScanReadouts(*pair, target.size());
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  if (avail.x < 10 || avail.y < 10) return ImGui::End();
  ImGui::InvisibleButton("scan_canvas", avail);
  const bool hovered = ImGui::IsItemHovered();
  const ScanCanvas canvas = FitScanCanvas(origin, avail, target, scan_zoom_);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, canvas.end(), true);
  draw->AddRectFilled(origin, canvas.end(), IM_COL32(22, 22, 27, 255));
  DrawScanGrid(draw, canvas);
  DrawScanPoints(draw, canvas, *pair, target);
  DrawScanSensors(draw, canvas, DisplayedEstimate(s));
  draw->PopClipRect();
  if (hovered && ImGui::GetIO().MouseWheel != 0)
    scan_zoom_ = std::clamp(scan_zoom_ * std::pow(1.25f, ImGui::GetIO().MouseWheel), 1.0f, 60.0f);
  ImGui::End();
}

}  // namespace calibench::ui
