#include "ui/lrf/workbench.h"

// clang-format off
// gl_api.h first: it declares GL for everything below.
#include "core/lrf/result_io.h"
#include "ui/gfx/gl_api.h"
// clang-format on

#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>

#include "core/geometry/geometry.h"
#include "core/lidar_camera/result_io.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/renderers.h"

namespace calibench::ui {

struct LrfWorkbench::Gl {
  gfx::ImageTexture picture;  // depth picture or RGB image of the selected pair
  gfx::Framebuffer scene_target;
  gfx::PointRenderer cloud_points, scan_points;
  gfx::LineRenderer scene_lines;
  gfx::TriangleRenderer scene_board;
  const void* cloud_source = nullptr;  // the features the cloud was built from
  Vec3 scene_center = Vec3(0, 0, 2);   // orbit target, camera frame (metres)
  double floor_y = 1.0;                // camera y of the grid (y down), metres
};

namespace {

constexpr ImGuiWindowFlags kViewFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;
constexpr ImGuiWindowFlags kPanelFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;

// Faces 0 (base), 1 (ABC), 2 (ACD): the same colours in every view. RGB.
constexpr std::uint8_t kFaceRgb[3][3] = {{80, 150, 255}, {240, 90, 200}, {70, 215, 120}};
constexpr const char* kFaceNames[3] = {"base", "ABC", "ACD"};
const ImU32 kScanInCamera = IM_COL32(255, 225, 40, 255);  // scan points moved into the camera
const ImU32 kBoardColor = IM_COL32(255, 150, 40, 255);

ImU32 FaceColor(int face, int alpha = 255) {
  return IM_COL32(kFaceRgb[face][0], kFaceRgb[face][1], kFaceRgb[face][2], alpha);
}
ImVec4 FaceColorVec(int face) {
  return {kFaceRgb[face][0] / 255.f, kFaceRgb[face][1] / 255.f, kFaceRgb[face][2] / 255.f, 1};
}

bool BeginView(const char* title, float x, float y, float w, float h) {
  ImGui::SetNextWindowPos({x, y});
  ImGui::SetNextWindowSize({w, h});
  return ImGui::Begin(title, nullptr, kViewFlags);
}

ImTextureID TextureId(std::uint32_t texture) {
  return reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture));
}

const LrfPairFeatures* SelectedFeatures(const LrfSnapshot& s) {
  if (s.selected < 0 || s.selected >= static_cast<int>(s.pairs.size())) return nullptr;
  return s.pairs[s.selected].features.get();
}

void Waiting(const LrfSnapshot& s) {
  if (!s.dataset)
    ImGui::TextDisabled("no dataset open");
  else
    ImGui::TextDisabled("extracting features: %d / %d pairs ...", s.extracted_done,
                        s.extracted_total);
}

// Scan points on the target, with their face (0..2; 3 = checkerboard).
std::vector<std::pair<Vec2, int>> TargetPoints(const LrfPairFeatures& pair) {
  std::vector<std::pair<Vec2, int>> points;
  if (pair.three_face)
    for (int face = 0; face < 3; ++face)
      for (const Vec2& p : pair.three_face->scan.face_points[face]) points.push_back({p, face});
  if (pair.board_scan)
    for (const Vec2& p : pair.board_scan->points) points.push_back({p, 3});
  return points;
}

// The depth frame as a grey picture (near bright) with the three faces tinted. BGR.
ImageU8 ComposeDepthPicture(const DepthImage& depth, const DepthFeatures& features) {
  const int w = depth.intrinsics.width, h = depth.intrinsics.height;
  std::vector<float> valid;
  for (float z : depth.depth_m)
    if (z > 0) valid.push_back(z);
  float lo = 0, hi = 1;
  if (!valid.empty()) {
    std::sort(valid.begin(), valid.end());
    lo = valid[valid.size() / 50];
    hi = std::max(lo + 1e-3f, valid[valid.size() - 1 - valid.size() / 50]);
  }
  ImageU8 picture{w, h, 3, std::vector<std::uint8_t>(static_cast<size_t>(w) * h * 3)};
  const bool has_faces = features.face_of_pixel.size() == depth.depth_m.size();
  for (size_t i = 0; i < depth.depth_m.size(); ++i) {
    std::uint8_t* p = picture.data.data() + 3 * i;
    const float z = depth.depth_m[i];
    if (z <= 0) {
      p[0] = 48, p[1] = 36, p[2] = 32;  // no data: dark blue-grey
      continue;
    }
    const float t = std::clamp((z - lo) / (hi - lo), 0.0f, 1.0f);
    const float grey = 225.0f - 165.0f * t;
    float rgb[3] = {grey, grey, grey};
    const int face = has_faces ? features.face_of_pixel[i] : -1;
    if (face >= 0 && face < 3)
      for (int c = 0; c < 3; ++c) rgb[c] = 0.4f * grey + 0.6f * kFaceRgb[face][c];
    for (int c = 0; c < 3; ++c) p[2 - c] = static_cast<std::uint8_t>(rgb[c]);
  }
  return picture;
}

// A camera-frame point in the shown image's pixels: the depth intrinsics (three-face) or the RGB
// camera model (checkerboard).
std::optional<Vec2> ProjectToImage(const LrfDataset& dataset, const Vec3& x) {
  if (dataset.target_type == LrfTargetType::kCheckerboard) return dataset.camera.Project(x);
  if (x.z() < 0.05) return std::nullopt;
  const DepthIntrinsics& k = dataset.depth_camera;
  return Vec2(k.fx * x.x() / x.z() + k.cx, k.fy * x.y() / x.z() + k.cy);
}

Vec3 OnScanPlane(const Vec2& p) { return Vec3(p.x(), p.y(), 0.0); }

// Constructs the intent in place (a moved temporary variant trips GCC 12's
// -Wmaybe-uninitialized).
template <typename T, typename... Args>
void Emit(std::vector<LrfIntent>* intents, Args&&... args) {
  intents->emplace_back(std::in_place_type<T>, T{std::forward<Args>(args)...});
}

}  // namespace

bool ParseLrfLayout(const std::string& name, LrfLayout* layout) {
  if (name == "workbench")
    *layout = LrfLayout::kWorkbench;
  else if (name == "scan")
    *layout = LrfLayout::kScanOnly;
  else if (name == "depth")
    *layout = LrfLayout::kDepthOnly;
  else if (name == "3d")
    *layout = LrfLayout::kSceneOnly;
  else
    return false;
  return true;
}

LrfWorkbench::LrfWorkbench() : gl_(std::make_unique<Gl>()) {}
LrfWorkbench::~LrfWorkbench() = default;

const Pose* LrfWorkbench::DisplayedEstimate(const LrfSnapshot& s) const {
  const auto& iterations = s.solver.iterations;
  if (!iterations.empty()) {
    const int last = static_cast<int>(iterations.size()) - 1;
    const int index =
        replay_position_ < 0 ? last : std::min(last, static_cast<int>(replay_position_));
    return &iterations[index].cam_from_lidar;  // IterationReport names it for the 3D method
  }
  return s.solver.solution ? &s.solver.solution->cam_from_lrf : nullptr;
}

std::vector<LrfIntent> LrfWorkbench::Frame(const LrfSnapshot& s, int width, int height,
                                           LrfLayout layout, double seconds_since_last_frame) {
  std::vector<LrfIntent> intents;
  if (replaying_ && !s.solver.iterations.empty()) {
    replay_position_ = std::max(0.0, replay_position_) + 2.0 * seconds_since_last_frame;  // 2 it/s
    if (replay_position_ >= static_cast<double>(s.solver.iterations.size()) - 1) {
      replay_position_ = -1;
      replaying_ = false;
    }
  }
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  switch (layout) {
    case LrfLayout::kScanOnly:
      ScanView(s, {0, 0, w, h});
      return intents;
    case LrfLayout::kDepthOnly:
      ImageView(s, {0, 0, w, h});
      return intents;
    case LrfLayout::kSceneOnly:
      SceneView(s, {0, 0, w, h});
      return intents;
    case LrfLayout::kWorkbench:
      break;
  }
  const float status_h = ImGui::GetFrameHeightWithSpacing() + 8;
  const float top_h = std::floor((h - status_h) * 0.58f);
  const float third = std::floor(w / 3);
  ScanView(s, {0, 0, third, top_h});
  ImageView(s, {third, 0, third, top_h});
  SceneView(s, {2 * third, 0, w - 2 * third, top_h});
  const float bottom_h = h - status_h - top_h, left_w = std::floor(w * 0.5f);
  MeasurementsPanel(s, {0, top_h, left_w, bottom_h}, &intents);
  SolverPanel(s, {left_w, top_h, w - left_w, bottom_h}, &intents);
  StatusLine(s, {0, h - status_h, w, status_h});
  HandleKeys(s, &intents);
  return intents;
}

void LrfWorkbench::ScanView(const LrfSnapshot& s, const ViewRect& r) {
  if (!BeginView("Scan (LRF frame, top-down)", r.x, r.y, r.w, r.h)) return ImGui::End();
  const LrfPairFeatures* pair = SelectedFeatures(s);
  if (!pair) {
    Waiting(s);
    return ImGui::End();
  }
  const LaserScan& scan = pair->scan;
  const auto target = TargetPoints(*pair);
  if (pair->three_face && pair->three_face->scan.ok) {
    ImGui::Text("%zu rays, %zu on the target, line RMS %.1f mm", scan.ranges.size(), target.size(),
                pair->three_face->scan.rms_m * 1e3);
  } else if (pair->board_scan && pair->board_scan->ok) {
    ImGui::Text("%zu rays, %zu on the board, line RMS %.1f mm", scan.ranges.size(), target.size(),
                pair->board_scan->rms_m * 1e3);
  } else {
    const std::string why = pair->three_face   ? pair->three_face->scan.reason
                            : pair->board_scan ? pair->board_scan->reason
                                               : pair->reason;
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no target: %s", why.c_str());
  }
  for (int face = 0; face < 3 && pair->three_face; ++face) {
    ImGui::TextColored(FaceColorVec(face), "%s", kFaceNames[face]);
    ImGui::SameLine();
  }
  ImGui::TextDisabled("rings: F G H   wheel: zoom about the target");

  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  if (avail.x < 10 || avail.y < 10) return ImGui::End();
  ImGui::InvisibleButton("scan_canvas", avail);
  const bool hovered = ImGui::IsItemHovered();
  // Fit the LRF origin and the target (margin 0.4 m); the wheel zooms about the target's centre.
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
  // Screen right = LRF -y, screen up = LRF +x.
  const double fit = std::min(avail.x / (hi.y() - lo.y()), avail.y / (hi.x() - lo.x()));
  const double scale = fit * scan_zoom_;  // pixels per metre
  const Vec2 center = target_center + ((lo + hi) / 2 - target_center) / scan_zoom_;
  const ImVec2 mid(origin.x + avail.x / 2, origin.y + avail.y / 2);
  auto to_screen = [&](const Vec2& p) {
    return ImVec2(mid.x - static_cast<float>((p.y() - center.y()) * scale),
                  mid.y - static_cast<float>((p.x() - center.x()) * scale));
  };
  const ImVec2 end(origin.x + avail.x, origin.y + avail.y);
  auto inside = [&](const ImVec2& q) {
    return q.x >= origin.x && q.x <= end.x && q.y >= origin.y && q.y <= end.y;
  };
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, end, true);
  draw->AddRectFilled(origin, end, IM_COL32(22, 22, 27, 255));
  // Metre grid: the smallest of 0.1 / 0.2 / 0.5 / 1 / 2 / 5 m at least 45 px apart.
  double spacing = 5.0;
  for (double candidate : {0.1, 0.2, 0.5, 1.0, 2.0, 5.0})
    if (candidate * scale >= 45) {
      spacing = candidate;
      break;
    }
  const double half_x = avail.y / 2 / scale, half_y = avail.x / 2 / scale;
  for (int k = static_cast<int>(std::floor((center.x() - half_x) / spacing));
       k * spacing <= center.x() + half_x; ++k) {
    const float y = to_screen(Vec2(k * spacing, 0)).y;
    draw->AddLine({origin.x, y}, {end.x, y},
                  k == 0 ? IM_COL32(95, 95, 105, 255) : IM_COL32(50, 50, 58, 255));
    char label[32];
    std::snprintf(label, sizeof(label), "x %g m", k * spacing);
    draw->AddText({origin.x + 3, y - 15}, IM_COL32(120, 120, 130, 255), label);
  }
  for (int k = static_cast<int>(std::floor((center.y() - half_y) / spacing));
       k * spacing <= center.y() + half_y; ++k) {
    const float x = to_screen(Vec2(0, k * spacing)).x;
    draw->AddLine({x, origin.y}, {x, end.y},
                  k == 0 ? IM_COL32(95, 95, 105, 255) : IM_COL32(50, 50, 58, 255));
    char label[32];
    std::snprintf(label, sizeof(label), "y %g", k * spacing);
    draw->AddText({x + 3, end.y - 16}, IM_COL32(120, 120, 130, 255), label);
  }
  // Every return in grey, the target's points coloured by face.
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.Valid(i)) continue;
    const ImVec2 q = to_screen(scan.Point(i));
    if (inside(q))
      draw->AddRectFilled({q.x - 1, q.y - 1}, {q.x + 1, q.y + 1}, IM_COL32(150, 150, 158, 255));
  }
  for (const auto& [p, face] : target)
    draw->AddCircleFilled(to_screen(p), 2.5f, face < 3 ? FaceColor(face) : kBoardColor, 8);
  // The fitted lines as segments over their points' extent (plus 5 cm).
  auto draw_line = [&](const Line2& line, const std::vector<Vec2>& points, ImU32 color) {
    if (points.empty()) return;
    const Vec2 direction(-line.normal.y(), line.normal.x());
    const Vec2 foot = -line.normal * line.offset;
    double t0 = 1e9, t1 = -1e9;
    for (const Vec2& p : points)
      t0 = std::min(t0, (p - foot).dot(direction)), t1 = std::max(t1, (p - foot).dot(direction));
    draw->AddLine(to_screen(foot + (t0 - 0.05) * direction),
                  to_screen(foot + (t1 + 0.05) * direction), color, 1.5f);
  };
  if (pair->three_face && pair->three_face->scan.ok) {
    const ScanFeatures& features = pair->three_face->scan;
    for (int face = 0; face < 3; ++face)
      draw_line(features.lines[face], features.face_points[face], FaceColor(face, 200));
    constexpr const char* kCorners[3] = {"F", "G", "H"};
    for (int c = 0; c < 3; ++c) {
      const ImVec2 q = to_screen(features.corners[c]);
      draw->AddCircle(q, 6.0f, IM_COL32(255, 255, 255, 255), 16, 2.0f);
      draw->AddText({q.x + 8, q.y - 8}, IM_COL32(255, 255, 255, 255), kCorners[c]);
    }
  }
  if (pair->board_scan && pair->board_scan->ok)
    draw_line(pair->board_scan->line, pair->board_scan->points, kBoardColor);
  // The LRF: x forward (red, up the screen), y left (green).
  const ImVec2 o = to_screen(Vec2::Zero());
  draw->AddLine(o, {o.x, o.y - 40}, IM_COL32(255, 70, 70, 255), 2.0f);
  draw->AddLine(o, {o.x - 40, o.y}, IM_COL32(70, 230, 70, 255), 2.0f);
  draw->AddCircleFilled(o, 4.0f, IM_COL32(235, 235, 235, 255), 12);
  draw->AddText({o.x + 6, o.y + 2}, IM_COL32(235, 235, 235, 255), "LRF");
  // After a solve: the camera's centre and optical axis seen from above.
  if (const Pose* estimate = DisplayedEstimate(s)) {
    const Pose lrf_from_cam = estimate->inverse();
    const Vec3 c = lrf_from_cam.translation(), axis = lrf_from_cam.linear().col(2);
    const ImVec2 q = to_screen(c.head<2>());
    draw->AddLine(q, to_screen(c.head<2>() + 0.3 * axis.head<2>()), IM_COL32(80, 220, 255, 255),
                  2.0f);
    draw->AddCircleFilled(q, 4.0f, IM_COL32(80, 220, 255, 255), 12);
    draw->AddText({q.x + 6, q.y - 16}, IM_COL32(80, 220, 255, 255), "camera");
  }
  draw->PopClipRect();
  if (hovered && ImGui::GetIO().MouseWheel != 0)
    scan_zoom_ = std::clamp(scan_zoom_ * std::pow(1.25f, ImGui::GetIO().MouseWheel), 1.0f, 60.0f);
  ImGui::End();
}

void LrfWorkbench::ImageView(const LrfSnapshot& s, const ViewRect& r) {
  const bool board_case = s.dataset && s.dataset->target_type == LrfTargetType::kCheckerboard;
  if (!BeginView(board_case ? "Camera image" : "Depth image", r.x, r.y, r.w, r.h))
    return ImGui::End();
  const LrfPairFeatures* pair = SelectedFeatures(s);
  if (!pair) {
    Waiting(s);
    return ImGui::End();
  }
  const void* source = nullptr;
  if (board_case) {
    if (pair->camera)
      ImGui::Text("board: %d corners, reprojection RMS %.2f px, %.2f m away",
                  pair->camera->num_corners, pair->camera->reprojection_rms_px,
                  pair->camera->plane.distance);
    else
      ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "board not found: %s", pair->reason.c_str());
    source = s.selected_image.get();
  } else if (pair->three_face) {
    const DepthFeatures& d = pair->three_face->depth;
    if (d.ok)
      ImGui::Text("faces %d / %d / %d px, plane RMS %.1f mm, smallest angle %.0f deg",
                  d.inlier_counts[0], d.inlier_counts[1], d.inlier_counts[2], d.rms_m * 1e3,
                  d.min_face_angle_deg);
    else
      ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no faces: %s", d.reason.c_str());
    if (pair->depth) source = pair;
  }
  const Pose* estimate = DisplayedEstimate(s);
  ImGui::TextDisabled(estimate ? "yellow: the scan moved into the camera; rings: F G H"
                               : "run the solver to project the scan into this image");
  if (!source) {
    ImGui::TextDisabled(board_case ? "loading image ..." : "no depth frame: %s",
                        pair->reason.c_str());
    return ImGui::End();
  }
  if (reinterpret_cast<std::uintptr_t>(source) != image_key_) {
    image_key_ = reinterpret_cast<std::uintptr_t>(source);
    if (board_case)
      gl_->picture.Upload(*s.selected_image, true);
    else
      gl_->picture.Upload(ComposeDepthPicture(*pair->depth, pair->three_face->depth), false);
  }
  const int iw = gl_->picture.width(), ih = gl_->picture.height();
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float fit = std::min(avail.x / iw, avail.y / ih);
  const float tw = std::max(1.0f, std::floor(iw * fit)), th = std::max(1.0f, std::floor(ih * fit));
  // Zoom and pan: the visible part is [u0, u0 + span] x [v0, v0 + span] (fractions of the image).
  const float span = 1.0f / image_zoom_;
  image_center_x_ = std::clamp(image_center_x_, span / 2, 1 - span / 2);
  image_center_y_ = std::clamp(image_center_y_, span / 2, 1 - span / 2);
  const float u0 = image_center_x_ - span / 2, v0 = image_center_y_ - span / 2;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(TextureId(gl_->picture.texture()), ImVec2(tw, th), ImVec2(u0, v0),
               ImVec2(u0 + span, v0 + span));
  const bool hovered = ImGui::IsItemHovered();
  auto to_screen = [&](const Vec2& px) {
    return ImVec2(origin.x + static_cast<float>(((px.x() + 0.5) / iw - u0) / span * tw),
                  origin.y + static_cast<float>(((px.y() + 0.5) / ih - v0) / span * th));
  };
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, ImVec2(origin.x + tw, origin.y + th), true);
  if (board_case && pair->camera) {
    const double hw = s.dataset->board.SheetWidth() / 2, hh = s.dataset->board.SheetHeight() / 2;
    const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
    std::vector<ImVec2> outline;
    for (int e = 0; e < 4; ++e)
      for (int k = 0; k < 16; ++k)
        if (const auto px = ProjectToImage(
                *s.dataset, pair->camera->cam_from_board *
                                (corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 16.0))))
          outline.push_back(to_screen(*px));
    if (outline.size() > 2)
      draw->AddPolyline(outline.data(), static_cast<int>(outline.size()),
                        IM_COL32(80, 200, 255, 255), ImDrawFlags_Closed, 2.0f);
  }
  if (estimate) {
    // Every return moved into the camera by the estimate, the target's larger and outlined.
    const LaserScan& scan = pair->scan;
    for (size_t i = 0; i < scan.ranges.size(); ++i)
      if (scan.Valid(i))
        if (const auto px = ProjectToImage(*s.dataset, *estimate * OnScanPlane(scan.Point(i))))
          draw->AddCircleFilled(to_screen(*px), 1.5f, kScanInCamera, 6);
    // Outlines first, then the fills: the target's returns are dense.
    std::vector<ImVec2> on_target;
    for (const auto& [p, face] : TargetPoints(*pair))
      if (const auto px = ProjectToImage(*s.dataset, *estimate * OnScanPlane(p)))
        on_target.push_back(to_screen(*px));
    for (const ImVec2& q : on_target) draw->AddCircleFilled(q, 3.2f, IM_COL32(0, 0, 0, 255), 8);
    for (const ImVec2& q : on_target) draw->AddCircleFilled(q, 2.0f, kScanInCamera, 8);
    if (pair->three_face && pair->three_face->scan.ok) {
      constexpr const char* kCorners[3] = {"F", "G", "H"};
      for (int c = 0; c < 3; ++c)
        if (const auto px = ProjectToImage(
                *s.dataset, *estimate * OnScanPlane(pair->three_face->scan.corners[c]))) {
          const ImVec2 q = to_screen(*px);
          draw->AddCircle(q, 6.0f, IM_COL32(255, 255, 255, 255), 16, 2.0f);
          draw->AddText({q.x + 8, q.y - 8}, IM_COL32(255, 255, 255, 255), kCorners[c]);
        }
    }
  }
  draw->PopClipRect();
  if (hovered) {
    const ImGuiIO& io = ImGui::GetIO();
    if (io.MouseWheel != 0) {
      // Zoom about the pixel under the mouse.
      const float mx = u0 + (io.MousePos.x - origin.x) / tw * span;
      const float my = v0 + (io.MousePos.y - origin.y) / th * span;
      image_zoom_ = std::clamp(image_zoom_ * std::pow(1.25f, io.MouseWheel), 1.0f, 32.0f);
      const float new_span = 1.0f / image_zoom_;
      image_center_x_ = mx - (io.MousePos.x - origin.x) / tw * new_span + new_span / 2;
      image_center_y_ = my - (io.MousePos.y - origin.y) / th * new_span + new_span / 2;
    }
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
      image_center_x_ -= io.MouseDelta.x / tw * span;
      image_center_y_ -= io.MouseDelta.y / th * span;
    }
  }
  ImGui::End();
}

void LrfWorkbench::DrawScene(const LrfSnapshot& s, const LrfPairFeatures& pair,
                             const gfx::Matrix4f& view_projection, const Pose* estimate, int tw,
                             int th) {
  std::vector<Eigen::Vector3f> lines;
  std::vector<gfx::Rgba> line_colors;
  auto add_line = [&](const Vec3& a, const Vec3& b, gfx::Rgba c) {
    lines.push_back(a.cast<float>());
    lines.push_back(b.cast<float>());
    line_colors.push_back(c);
    line_colors.push_back(c);
  };
  // A 0.5 m grid on the floor (camera y points down), around and behind the target.
  const Vec3& c = gl_->scene_center;
  const double x0 = std::round(c.x()) - 4, z1 = std::ceil(c.z()) + 3, y = gl_->floor_y;
  const gfx::Rgba grid{62, 62, 70, 255};
  for (int k = 0; k <= 16; ++k) add_line({x0 + 0.5 * k, y, 0}, {x0 + 0.5 * k, y, z1}, grid);
  for (int k = 0; k <= 2 * z1; ++k) add_line({x0, y, 0.5 * k}, {x0 + 8, y, 0.5 * k}, grid);
  auto add_axes = [&](const Pose& cam_from_frame, double length) {
    const gfx::Rgba colors[3] = {{255, 60, 60, 255}, {60, 230, 60, 255}, {80, 120, 255, 255}};
    for (int a = 0; a < 3; ++a)
      add_line(cam_from_frame.translation(), cam_from_frame * (Vec3::Unit(a) * length), colors[a]);
  };
  add_axes(Pose::Identity(), 0.3);         // the camera
  if (estimate) add_axes(*estimate, 0.3);  // the LRF at the estimate
  std::vector<Eigen::Vector3f> quad;
  std::vector<gfx::Rgba> quad_colors;
  if (pair.camera) {
    const double hw = s.dataset->board.SheetWidth() / 2, hh = s.dataset->board.SheetHeight() / 2;
    const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
    for (int k : {0, 1, 2, 0, 2, 3}) {
      quad.push_back((pair.camera->cam_from_board * corners[k]).cast<float>());
      quad_colors.push_back({255, 150, 40, 110});
    }
  }
  std::vector<Eigen::Vector3f> scan;
  if (estimate)
    for (size_t i = 0; i < pair.scan.ranges.size(); ++i)
      if (pair.scan.Valid(i) && pair.scan.ranges[i] < 15.0)
        scan.push_back((*estimate * OnScanPlane(pair.scan.Point(i))).cast<float>());
  gl_->scene_target.Resize(tw, th);
  gl_->scene_target.Bind();
  gl_->scene_target.Clear(0.08f, 0.08f, 0.1f, 1.0f);
  gl_->scene_lines.Upload(lines, line_colors);
  gl_->scene_lines.Draw(view_projection);
  gl_->cloud_points.Draw(view_projection, 2.0f);
  gl_->scan_points.Upload(scan, std::vector<gfx::Rgba>(scan.size(), gfx::Rgba{255, 225, 40, 255}));
  gl_->scan_points.Draw(view_projection, 4.0f);
  gl_->scene_board.Upload(quad, quad_colors);
  gl_->scene_board.Draw(view_projection);
}

void LrfWorkbench::SceneView(const LrfSnapshot& s, const ViewRect& r) {
  if (!BeginView("3D (camera frame)", r.x, r.y, r.w, r.h)) return ImGui::End();
  const LrfPairFeatures* pair = SelectedFeatures(s);
  if (!pair) {
    Waiting(s);
    return ImGui::End();
  }
  const Pose* estimate = DisplayedEstimate(s);
  ImGui::TextDisabled(estimate ? "cloud by face; yellow: the scan at the estimate. drag: orbit, "
                                 "wheel: zoom"
                               : "cloud by face; run the solver to move the scan in. drag: orbit");
  if (gl_->cloud_source != pair) {
    // The depth frame back-projected (every stride-th pixel, at most ~40k points).
    gl_->cloud_source = pair;
    std::vector<Eigen::Vector3f> positions;
    std::vector<gfx::Rgba> colors;
    Vec3 face_sum = Vec3::Zero(), all_sum = Vec3::Zero();
    int face_count = 0;
    std::vector<double> heights;
    if (pair->depth) {
      const DepthImage& depth = *pair->depth;
      const DepthIntrinsics& k = depth.intrinsics;
      const auto* faces =
          pair->three_face && pair->three_face->depth.face_of_pixel.size() == depth.depth_m.size()
              ? &pair->three_face->depth.face_of_pixel
              : nullptr;
      const int stride =
          std::max(1, static_cast<int>(std::ceil(std::sqrt(k.width * k.height / 40000.0))));
      for (int v = 0; v < k.height; v += stride)
        for (int u = 0; u < k.width; u += stride) {
          const double z = depth.At(u, v);
          if (z <= 0) continue;
          const Vec3 x((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
          const int face = faces ? (*faces)[static_cast<size_t>(v) * k.width + u] : -1;
          positions.push_back(x.cast<float>());
          all_sum += x;
          heights.push_back(x.y());
          if (face >= 0 && face < 3) {
            colors.push_back({kFaceRgb[face][0], kFaceRgb[face][1], kFaceRgb[face][2], 255});
            face_sum += x;
            ++face_count;
          } else {
            const auto g = static_cast<std::uint8_t>(std::clamp(190.0 - 15.0 * z, 90.0, 190.0));
            colors.push_back({g, g, g, 255});
          }
        }
    }
    gl_->cloud_points.Upload(positions, colors);
    if (face_count)
      gl_->scene_center = face_sum / face_count;
    else if (pair->camera)
      gl_->scene_center = pair->camera->cam_from_board.translation();
    else if (!positions.empty())
      gl_->scene_center = all_sum / static_cast<double>(positions.size());
    if (!heights.empty()) {
      std::nth_element(heights.begin(), heights.begin() + heights.size() * 49 / 50, heights.end());
      gl_->floor_y = heights[heights.size() * 49 / 50];
    } else {
      gl_->floor_y = gl_->scene_center.y() + 1.0;
    }
  }
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int tw = std::max(1, static_cast<int>(avail.x)),
            th = std::max(1, static_cast<int>(avail.y));
  // Orbit about a point between the camera and the target, so that both stay in view.
  const Eigen::Vector3f target = (0.65 * gl_->scene_center).cast<float>();
  const float distance =
      orbit_distance_scale_ * std::max(0.5f, static_cast<float>(gl_->scene_center.norm()));
  const Eigen::Vector3f forward(std::cos(orbit_pitch_rad_) * std::sin(orbit_yaw_rad_),
                                std::sin(orbit_pitch_rad_),
                                std::cos(orbit_pitch_rad_) * std::cos(orbit_yaw_rad_));
  const gfx::Matrix4f view_projection =
      gfx::Perspective(0.9f, static_cast<float>(tw) / th, 0.05f, 200.0f) *
      gfx::LookAt(target - distance * forward, target, -Eigen::Vector3f::UnitY());
  // Redraw only when something shown changed: the pair, the view or the estimate.
  std::uint64_t key = reinterpret_cast<std::uintptr_t>(pair) ^ 0xcbf29ce484222325ull;
  auto mix = [&key](const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) key = (key ^ p[i]) * 0x100000001b3ull;
  };
  mix(view_projection.data(), sizeof(float) * 16);
  if (estimate) mix(estimate->matrix().data(), sizeof(double) * 16);
  if (key != scene_key_ || gl_->scene_target.width() != tw || gl_->scene_target.height() != th) {
    scene_key_ = key;
    DrawScene(s, *pair, view_projection, estimate, tw, th);
  }
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(TextureId(gl_->scene_target.color_texture()), ImVec2(tw, th), ImVec2(0, 1),
               ImVec2(1, 0));
  // Frame names next to their axes.
  auto label = [&](const Vec3& x, const char* text) {
    const Eigen::Vector4f clip = view_projection * Eigen::Vector4f(x.x(), x.y(), x.z(), 1.0f);
    if (clip.w() <= 0) return;
    const float u = (clip.x() / clip.w() + 1) / 2, v = (1 - clip.y() / clip.w()) / 2;
    if (u < 0 || u > 1 || v < 0 || v > 1) return;
    ImGui::GetWindowDrawList()->AddText({origin.x + u * tw + 4, origin.y + v * th + 2},
                                        IM_COL32(220, 220, 220, 255), text);
  };
  label(Vec3::Zero(), "camera");
  if (estimate) label(estimate->translation(), "LRF");
  if (ImGui::IsItemHovered()) {
    const ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      orbit_yaw_rad_ += io.MouseDelta.x * 0.01f;
      orbit_pitch_rad_ = std::clamp(orbit_pitch_rad_ + io.MouseDelta.y * 0.01f, -1.5f, 1.5f);
    }
    if (io.MouseWheel != 0)
      orbit_distance_scale_ =
          std::clamp(orbit_distance_scale_ * std::pow(0.85f, io.MouseWheel), 0.2f, 20.0f);
  }
  ImGui::End();
}

namespace {

ImVec4 StatusColor(PairStatus status) {
  switch (status) {
    case PairStatus::kAccepted:
      return {0.45f, 0.85f, 0.45f, 1};
    case PairStatus::kRejected:
      return {0.95f, 0.65f, 0.3f, 1};
    case PairStatus::kFailed:
      return {1.0f, 0.4f, 0.35f, 1};
    case PairStatus::kPending:
      return {0.7f, 0.7f, 0.7f, 1};
  }
  return {1, 1, 1, 1};
}

void TextMm(const std::optional<double>& metres) {
  if (metres) ImGui::Text("%.1f", *metres * 1e3);
}

}  // namespace

void LrfWorkbench::MeasurementsPanel(const LrfSnapshot& s, const ViewRect& r,
                                     std::vector<LrfIntent>* intents) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  if (!ImGui::Begin("Measurements", nullptr, kPanelFlags)) return ImGui::End();
  if (s.extracted_done < s.extracted_total) {
    char label[64];
    std::snprintf(label, sizeof(label), "extracting %d / %d pairs", s.extracted_done,
                  s.extracted_total);
    ImGui::ProgressBar(static_cast<float>(s.extracted_done) / std::max(1, s.extracted_total),
                       {-1, 0}, label);
  }
  ImGui::BeginDisabled(s.selected < 0);
  if (ImGui::Button("Accept (A)"))
    Emit<LrfSetPairStatus>(intents, s.selected, PairStatus::kAccepted);
  ImGui::SameLine();
  if (ImGui::Button("Reject (R)"))
    Emit<LrfSetPairStatus>(intents, s.selected, PairStatus::kRejected);
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("arrows: previous / next; figures in mm");
  const bool board_case = s.dataset && s.dataset->target_type == LrfTargetType::kCheckerboard;
  if (ImGui::BeginTable(
          "pairs", 7,
          ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_BordersInnerV,
          ImVec2(0, ImGui::GetContentRegionAvail().y))) {
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("pair", ImGuiTableColumnFlags_WidthFixed, 60);
    ImGui::TableSetupColumn("status", ImGuiTableColumnFlags_WidthFixed, 70);
    ImGui::TableSetupColumn("scan", ImGuiTableColumnFlags_WidthFixed, 45);
    ImGui::TableSetupColumn(board_case ? "PnP px" : "depth", ImGuiTableColumnFlags_WidthFixed, 50);
    ImGui::TableSetupColumn("Eq.12", ImGuiTableColumnFlags_WidthFixed, 50);
    ImGui::TableSetupColumn("plane", ImGuiTableColumnFlags_WidthFixed, 45);
    ImGui::TableSetupColumn("details", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    for (int i = 0; i < static_cast<int>(s.pairs.size()); ++i) {
      const LrfPairView& pair = s.pairs[i];
      const LrfPairFeatures* f = pair.features.get();
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::PushID(i);
      if (ImGui::Selectable(
              pair.id.c_str(), i == s.selected,
              ImGuiSelectableFlags_SpanAllColumns | ImGuiSelectableFlags_AllowItemOverlap))
        Emit<LrfSelectPair>(intents, i);
      ImGui::PopID();
      ImGui::TableNextColumn();
      ImGui::TextColored(StatusColor(pair.status), "%s",
                         pair.extracted ? PairStatusName(pair.status).c_str() : "extracting");
      ImGui::TableNextColumn();
      if (f && f->three_face && f->three_face->scan.ok) TextMm(f->three_face->scan.rms_m);
      if (f && f->board_scan && f->board_scan->ok) TextMm(f->board_scan->rms_m);
      ImGui::TableNextColumn();
      if (f && f->three_face && f->three_face->depth.ok) TextMm(f->three_face->depth.rms_m);
      if (f && f->camera) ImGui::Text("%.2f", f->camera->reprojection_rms_px);
      ImGui::TableNextColumn();
      TextMm(pair.point_to_line_m);
      ImGui::TableNextColumn();
      TextMm(pair.point_to_plane_rms_m);
      ImGui::TableNextColumn();
      if (!pair.reason.empty())
        ImGui::TextWrapped("%s", pair.reason.c_str());
      else if (f && f->three_face)
        ImGui::TextDisabled(
            "%zu scan points, faces %d / %d / %d px", f->three_face->scan.target_indices.size(),
            f->three_face->depth.inlier_counts[0], f->three_face->depth.inlier_counts[1],
            f->three_face->depth.inlier_counts[2]);
      else if (f && f->board_scan && f->camera)
        ImGui::TextDisabled("%zu board points, %d corners", f->board_scan->points.size(),
                            f->camera->num_corners);
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

void LrfWorkbench::SolverPanel(const LrfSnapshot& s, const ViewRect& r,
                               std::vector<LrfIntent>* intents) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  if (!ImGui::Begin("Solver", nullptr, kPanelFlags)) return ImGui::End();
  static const char* kMethods[] = {"paper-linear (Eq. 9-11)", "refined (point-to-plane GN)"};
  int method = s.solver.method == LrfMethod::kPaperLinear ? 0 : 1;
  ImGui::SetNextItemWidth(230);
  if (ImGui::Combo("method", &method, kMethods, 2))
    Emit<LrfSetMethod>(intents, method == 0 ? LrfMethod::kPaperLinear : LrfMethod::kRefined);
  const bool solved = !s.solver.iterations.empty();
  ImGui::BeginDisabled(s.solver.running);
  if (ImGui::Button("Run (F5)")) {
    Emit<LrfRunSolver>(intents);
    replay_position_ = -1;
    replaying_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Step")) {
    if (!solved) {
      Emit<LrfRunSolver>(intents);
      replay_position_ = 0;
    } else {
      replay_position_ = replay_position_ < 0 ? 0 : replay_position_ + 1;
      if (replay_position_ >= static_cast<double>(s.solver.iterations.size()) - 1)
        replay_position_ = -1;
    }
    replaying_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Replay") && solved) {
    replay_position_ = 0;
    replaying_ = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("Reset")) {
    Emit<LrfResetSolver>(intents);
    replay_position_ = -1;
  }
  ImGui::EndDisabled();
  if (s.solver.running) {
    ImGui::SameLine();
    ImGui::TextColored({0.95f, 0.8f, 0.3f, 1}, "solving ...");
  }
  if (solved) {
    std::vector<float> log_cost;
    for (const IterationReport& it : s.solver.iterations)
      log_cost.push_back(static_cast<float>(std::log10(std::max(it.cost, 1e-30))));
    const int shown = replay_position_ < 0 ? static_cast<int>(log_cost.size()) - 1
                                           : static_cast<int>(replay_position_);
    char overlay[96];
    std::snprintf(overlay, sizeof(overlay), "log10 cost; iteration %d of %zu: %.4e", shown,
                  log_cost.size() - 1, s.solver.iterations[shown].cost);
    ImGui::PlotLines("##cost", log_cost.data(), static_cast<int>(log_cost.size()), 0, overlay,
                     FLT_MAX, FLT_MAX, ImVec2(r.w * 0.55f, 60));
  } else if (s.solver.solution) {
    ImGui::TextDisabled("closed form (Eq. 11): no iterations to replay");
  }
  if (!s.solver.failure.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.solver.failure.c_str());
  if (s.solver.solution) {
    const LrfSolution& solution = *s.solver.solution;
    const Pose& pose = solution.cam_from_lrf;
    ImGui::Text("cam_from_lrf");
    ImGui::SameLine();
    ImGui::TextDisabled("(x_cam = cam_from_lrf * x_lrf)");
    for (int row = 0; row < 3; ++row)
      ImGui::Text("  % .5f % .5f % .5f | % .4f", pose.matrix()(row, 0), pose.matrix()(row, 1),
                  pose.matrix()(row, 2), pose.matrix()(row, 3));
    const Vec3& st = s.solver.std_translation_mm;
    const Vec3& sr = s.solver.std_rotation_deg;
    ImGui::Text("std (camera x/y/z): %.1f %.1f %.1f mm, %.3f %.3f %.3f deg", st.x(), st.y(), st.z(),
                sr.x(), sr.y(), sr.z());
    ImGui::Text(
        "%s over %zu pairs",
        LrfResidualText(solution, s.dataset ? s.dataset->target_type : LrfTargetType::kThreeFace)
            .c_str(),
        s.solver.solved_pair_ids.size());
    if (s.dataset && s.dataset->cam_from_lrf_ground_truth) {
      const Pose& truth = *s.dataset->cam_from_lrf_ground_truth;
      ImGui::TextDisabled("vs ground truth: %.1f mm, %.3f deg",
                          (pose.translation() - truth.translation()).norm() * 1e3,
                          RotationAngle(pose.linear(), truth.linear()) * 180.0 / M_PI);
    }
    if (solution.observability.well_constrained) {
      ImGui::TextColored({0.45f, 0.85f, 0.45f, 1}, "well constrained (%s, %d iterations%s)",
                         LrfMethodName(solution.method).c_str(), solution.iterations,
                         solution.method == LrfMethod::kRefined
                             ? (solution.converged ? ", converged" : ", not converged")
                             : "");
    } else {
      ImGui::TextColored({1.0f, 0.45f, 0.3f, 1},
                         "NOT well constrained: add observations with other target poses");
      for (const std::string& d : solution.observability.weak_directions)
        ImGui::TextColored({1.0f, 0.6f, 0.4f, 1}, "  weak: %s", d.c_str());
    }
    char path[512];
    std::snprintf(path, sizeof(path), "%s", export_path_.c_str());
    ImGui::SetNextItemWidth(220);
    if (ImGui::InputText("##export", path, sizeof(path))) export_path_ = path;
    ImGui::SameLine();
    if (ImGui::Button("Export result")) Emit<LrfExportResult>(intents, export_path_);
  }
  ImGui::End();
}

void LrfWorkbench::StatusLine(const LrfSnapshot& s, const ViewRect& r) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus);
  if (s.busy) {
    ImGui::TextColored({0.95f, 0.8f, 0.3f, 1}, "working");
    ImGui::SameLine();
  }
  if (s.status_is_error)
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.status_line.c_str());
  else
    ImGui::TextUnformatted(s.status_line.c_str());
  ImGui::SameLine(std::max(ImGui::GetCursorPosX() + 20, r.w - 420));
  ImGui::TextDisabled("dataset: %s", s.manifest.filename().string().c_str());
  ImGui::End();
}

// Dear ImGui 1.86 keys are the platform backend's codes: GLFW uses ASCII for letters, and the
// headless host maps the same codes (as in workbench.cpp).
namespace {
constexpr int kKeyF5 = 294;  // GLFW_KEY_F5
bool KeyPressed(int key) { return key >= 0 && ImGui::IsKeyPressed(key, false); }
bool NamedKeyPressed(ImGuiKey key) { return KeyPressed(ImGui::GetKeyIndex(key)); }
}  // namespace

void LrfWorkbench::HandleKeys(const LrfSnapshot& s, std::vector<LrfIntent>* intents) {
  if (ImGui::GetIO().WantTextInput || s.selected < 0) return;
  const int n = static_cast<int>(s.pairs.size());
  const bool ctrl = ImGui::GetIO().KeyCtrl;
  if (!ctrl && KeyPressed('A')) Emit<LrfSetPairStatus>(intents, s.selected, PairStatus::kAccepted);
  if (!ctrl && KeyPressed('R')) Emit<LrfSetPairStatus>(intents, s.selected, PairStatus::kRejected);
  if (NamedKeyPressed(ImGuiKey_DownArrow) || NamedKeyPressed(ImGuiKey_RightArrow))
    Emit<LrfSelectPair>(intents, std::min(n - 1, s.selected + 1));
  if (NamedKeyPressed(ImGuiKey_UpArrow) || NamedKeyPressed(ImGuiKey_LeftArrow))
    Emit<LrfSelectPair>(intents, std::max(0, s.selected - 1));
  if (NamedKeyPressed(ImGuiKey_Enter) || KeyPressed(kKeyF5)) Emit<LrfRunSolver>(intents);
}

}  // namespace calibench::ui
