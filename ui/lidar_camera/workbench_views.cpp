// The three views of the workbench: LiDAR image (brush), camera frame (corners, reprojection),
// 3D scene (cloud, planes, sensor frames).
#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/geometry.h"
#include "core/lidar/colormap.h"
#include "core/reproject/reproject.h"
#include "core/sim/sim.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"

namespace calibench::ui {
namespace {

constexpr ImGuiWindowFlags kViewFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;

bool BeginView(const char* title, float x, float y, float w, float h) {
  ImGui::SetNextWindowPos({x, y});
  ImGui::SetNextWindowSize({w, h});
  return ImGui::Begin(title, nullptr, kViewFlags);
}

ImTextureID TextureId(std::uint32_t texture) {
  return reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture));
}

gfx::Rgba ToRgba(const std::array<std::uint8_t, 3>& rgb, std::uint8_t alpha = 255) {
  return {rgb[0], rgb[1], rgb[2], alpha};
}

// The LiDAR picture with the brush (white veil) and the plane inliers (magenta: no perceptual
// colour map uses it) composed in.
ImageU8 ComposeLidarPicture(const PairView& pair, LidarChannel channel) {
  ImageU8 picture = RenderLidarImage(*pair.lidar_image, channel, Colormap::kTurbo);
  auto blend = [&](int pixel, int r, int g, int b, float alpha) {
    std::uint8_t* p = picture.data.data() + static_cast<size_t>(pixel) * picture.channels;
    p[0] = static_cast<std::uint8_t>(p[0] * (1 - alpha) + b * alpha);
    p[1] = static_cast<std::uint8_t>(p[1] * (1 - alpha) + g * alpha);
    p[2] = static_cast<std::uint8_t>(p[2] * (1 - alpha) + r * alpha);
  };
  for (int pixel : pair.brush_pixels) blend(pixel, 255, 255, 255, 0.45f);
  if (pair.lidar)
    for (int i : pair.lidar->inliers)
      if (pair.lidar_image->pixel_of_point[i] >= 0)
        blend(pair.lidar_image->pixel_of_point[i], 255, 40, 220, 0.9f);
  return picture;
}

void DrawEllipse(ImDrawList* draw, ImVec2 centre, float rx, float ry, ImU32 color) {
  constexpr int kSegments = 48;
  ImVec2 points[kSegments];
  for (int i = 0; i < kSegments; ++i) {
    const float a = 2.0f * static_cast<float>(M_PI) * i / kSegments;
    points[i] = ImVec2(centre.x + rx * std::cos(a), centre.y + ry * std::sin(a));
  }
  draw->AddPolyline(points, kSegments, color, ImDrawFlags_Closed, 1.5f);
}

}  // namespace

void Workbench::LidarView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents) {
  if (!BeginView("LiDAR image", r.x, r.y, r.w, r.h)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  if (!pair || !pair->lidar_image) {
    ImGui::TextDisabled(s.loading_total ? "loading %d / %d pairs ..." : "no dataset open",
                        s.loading_done, s.loading_total);
    return ImGui::End();
  }
  const LidarImage& image = *pair->lidar_image;
  // Header: channel, brush radius, plane quality.
  static const char* kChannels[] = {"intensity", "range", "ring"};
  int channel = static_cast<int>(s.view.lidar_channel);
  ImGui::SetNextItemWidth(110);
  if (ImGui::Combo("##channel", &channel, kChannels, 3)) {
    ViewState view = s.view;
    view.lidar_channel = static_cast<LidarChannel>(channel);
    intents->push_back(SetView{view});
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(110);
  float radius = static_cast<float>(s.view.brush_radius_px);
  if (ImGui::SliderFloat("brush [ ]", &radius, 1.0f, 60.0f, "%.0f px")) {
    ViewState view = s.view;
    view.brush_radius_px = radius;
    intents->push_back(SetView{view});
  }
  ImGui::SameLine();
  if (ImGui::SmallButton("clear")) intents->push_back(ClearBrush{s.selected});
  if (pair->lidar) {
    ImGui::Text("plane: %zu inliers of %d, RMS %.1f mm", pair->lidar->inliers.size(),
                pair->lidar->num_candidates, pair->lidar->rms_m * 1e3);
  } else {
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no plane: %s", pair->lidar_failure.c_str());
  }

  const std::uint64_t key = reinterpret_cast<std::uintptr_t>(pair->lidar_image.get()) ^
                            (pair->brush_pixels.size() * 2654435761ull) ^
                            ((pair->lidar ? pair->lidar->inliers.size() + 1 : 0) << 20) ^
                            (static_cast<std::uint64_t>(channel) << 40);
  if (key != lidar_key_) {
    gl_->lidar_picture.Upload(ComposeLidarPicture(*pair, s.view.lidar_channel), false);
    lidar_key_ = key;
  }
  // A newly selected pair opens centred on its brush (the board), not on a fixed azimuth.
  if (lidar_centered_on_ != pair->id && !pair->brush_pixels.empty()) {
    // Circular mean: the brush may straddle the image's left/right seam.
    double sx = 0, sy = 0;
    for (int pixel : pair->brush_pixels) {
      const double a = 2 * M_PI * ((pixel % image.columns) + 0.5) / image.columns;
      sx += std::cos(a), sy += std::sin(a);
    }
    const double mean = std::atan2(sy, sx);
    lidar_center_ = static_cast<float>((mean < 0 ? mean + 2 * M_PI : mean) / (2 * M_PI));
    lidar_centered_on_ = pair->id;
  }
  // Horizontal zoom around lidar_center_; rows stretched to the view height.
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float span = 1.0f / std::max(1.0f, lidar_zoom_);
  lidar_center_ = std::clamp(lidar_center_, span / 2, 1 - span / 2);
  const ImVec2 uv0(lidar_center_ - span / 2, 0), uv1(lidar_center_ + span / 2, 1);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(TextureId(gl_->lidar_picture.texture()), avail, uv0, uv1);
  lidar_image_rect_ = {origin.x, origin.y, avail.x, avail.y, uv0.x, uv1.x};
  const float px_per_col = avail.x / (span * image.columns);
  const float px_per_row = avail.y / image.rows;
  auto to_image = [&](ImVec2 screen, float* col, float* row) {
    *col = (uv0.x + (screen.x - origin.x) / avail.x * span) * image.columns;
    *row = (screen.y - origin.y) / avail.y * image.rows;
  };
  if (ImGui::IsItemHovered()) {
    const ImGuiIO& io = ImGui::GetIO();
    float col, row;
    to_image(io.MousePos, &col, &row);
    // The brush outline: a circle in LiDAR pixels, an ellipse on screen.
    ImDrawList* draw = ImGui::GetWindowDrawList();
    const float rad = static_cast<float>(s.view.brush_radius_px);
    DrawEllipse(draw, io.MousePos, rad * px_per_col, rad * px_per_row,
                io.KeyShift ? IM_COL32(255, 120, 90, 255) : IM_COL32(255, 255, 255, 220));
    if (ImGui::IsMouseDown(ImGuiMouseButton_Left))
      intents->push_back(
          BrushStroke{s.selected, static_cast<int>(row), static_cast<int>(col), rad, io.KeyShift});
    if (io.MouseWheel != 0)
      lidar_zoom_ = std::clamp(lidar_zoom_ * std::pow(1.25f, io.MouseWheel), 1.0f, 40.0f);
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Right))
      lidar_center_ -= io.MouseDelta.x / avail.x * span;
  }
  ImGui::End();
}

void Workbench::CameraView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents) {
  if (!BeginView("Camera", r.x, r.y, r.w, r.h)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  if (!pair || !s.selected_image || !s.dataset) {
    ImGui::TextDisabled("loading image ...");
    return ImGui::End();
  }
  ViewState view = s.view;
  static const char* kModes[] = {"raw", "undistorted"};
  int mode = static_cast<int>(view.camera_image);
  ImGui::SetNextItemWidth(110);
  if (ImGui::Combo("##mode", &mode, kModes, 2))
    view.camera_image = static_cast<CameraImageMode>(mode);
  static const char* kVisibility[] = {"hidden-point removal", "z-buffer", "no occlusion"};
  int visibility = static_cast<int>(view.visibility);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(150);
  if (ImGui::Combo("##visibility", &visibility, kVisibility, 3))
    view.visibility = static_cast<VisibilityMode>(visibility);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70);
  float size = static_cast<float>(view.point_size_px),
        opacity = static_cast<float>(view.point_opacity);
  if (ImGui::SliderFloat("size", &size, 1.0f, 8.0f, "%.1f")) view.point_size_px = size;
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70);
  if (ImGui::SliderFloat("opacity", &opacity, 0.1f, 1.0f, "%.2f")) view.point_opacity = opacity;
  if (view.visibility == VisibilityMode::kHpr) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(70);
    float exponent = static_cast<float>(view.hpr_radius_exponent);
    if (ImGui::SliderFloat("HPR 10^", &exponent, 1.0f, 4.0f, "%.1f"))
      view.hpr_radius_exponent = exponent;
  }
  if (!(view == s.view)) intents->push_back(SetView{view});
  if (pair->camera) {
    ImGui::Text("board: %d corners, reprojection RMS %.2f px, %.2f m away",
                pair->camera->num_corners, pair->camera->reprojection_rms_px,
                pair->camera->plane.distance);
  } else {
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "board not found: %s", pair->camera_failure.c_str());
  }

  // What is shown: the raw image with the real lens, or the undistorted one with its pinhole.
  const bool undistorted =
      s.view.camera_image == CameraImageMode::kUndistorted && s.selected_undistorted;
  const ImageU8& image = undistorted ? s.selected_undistorted->image : *s.selected_image;
  const CameraModel& lens = s.dataset->camera;
  const CameraModel& shown = undistorted ? s.selected_undistorted->pinhole : lens;
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float fit = std::min(avail.x / image.width, avail.y / image.height);
  const int tw = std::max(1, static_cast<int>(image.width * fit));
  const int th = std::max(1, static_cast<int>(image.height * fit));
  // Zoom and pan: the visible part of the image is [u0, u0 + span] x [v0, v0 + span] (fractions).
  const float span = 1.0f / camera_zoom_;
  camera_center_x_ = std::clamp(camera_center_x_, span / 2, 1 - span / 2);
  camera_center_y_ = std::clamp(camera_center_y_, span / 2, 1 - span / 2);
  const float u0 = camera_center_x_ - span / 2, v0 = camera_center_y_ - span / 2;
  // Image pixel -> NDC of the view's framebuffer (y up) and -> screen.
  auto to_ndc = [&](const Vec2& px) {
    return Eigen::Vector3f(static_cast<float>(((px.x() + 0.5) / image.width - u0) / span * 2 - 1),
                           static_cast<float>(1 - ((px.y() + 0.5) / image.height - v0) / span * 2),
                           0.0f);
  };
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  auto to_screen = [&](const Vec2& px) {
    return ImVec2(origin.x + static_cast<float>(((px.x() + 0.5) / image.width - u0) / span * tw),
                  origin.y + static_cast<float>(((px.y() + 0.5) / image.height - v0) / span * th));
  };
  // A raw-image pixel as shown (through the pinhole when undistorted).
  auto shown_pixel = [&](const Vec2& raw) -> std::optional<Vec2> {
    if (!undistorted) return raw;
    const auto ray = lens.Unproject(raw);
    return ray ? shown.Project(*ray) : std::nullopt;
  };
  const bool show_points = s.reprojection && s.reprojection->pair_id == pair->id && s.solver.result;
  const std::uint64_t key =
      reinterpret_cast<std::uintptr_t>(&image) ^
      (show_points ? reinterpret_cast<std::uintptr_t>(s.reprojection.get()) << 1 : 0) ^
      (static_cast<std::uint64_t>(tw) << 48) ^ (static_cast<std::uint64_t>(th) << 36) ^
      static_cast<std::uint64_t>(view.point_size_px * 1000) * 7919 ^
      static_cast<std::uint64_t>(view.point_opacity * 1000) * 104729 ^
      static_cast<std::uint64_t>(camera_zoom_ * 1e4) * 15485863 ^
      static_cast<std::uint64_t>(camera_center_x_ * 1e6) * 32452843 ^
      static_cast<std::uint64_t>(camera_center_y_ * 1e6) * 49979687;
  if (key != camera_key_) {
    camera_key_ = key;
    if (gl_->camera_image_source != &image) {
      gl_->camera_image.Upload(image, true);
      gl_->camera_image_source = &image;
    }
    gl_->camera_target.Resize(tw, th);
    gl_->camera_target.Bind();
    gl_->camera_target.Clear(0.1f, 0.1f, 0.1f, 1.0f);
    const Eigen::Vector3f top_left = to_ndc({-0.5, -0.5});
    const Eigen::Vector3f bottom_right = to_ndc({image.width - 0.5, image.height - 0.5});
    gl_->camera_image.Draw(top_left.x(), bottom_right.y(), bottom_right.x(), top_left.y());
    if (show_points) {
      std::vector<Eigen::Vector3f> positions;
      std::vector<gfx::Rgba> colors;
      const Reprojection& rp = *s.reprojection;
      const Pose& cam_from_lidar = s.solver.result->cam_from_lidar;
      for (size_t i = 0; i < rp.points.size(); ++i) {
        if (!rp.visible.empty() && !rp.visible[i]) continue;
        std::optional<Vec2> px = rp.points[i].pixel;
        if (undistorted)
          px = shown.Project(cam_from_lidar *
                             pair->cloud->points[rp.points[i].index].cast<double>());
        if (!px) continue;
        positions.push_back(to_ndc(*px));
        colors.push_back(ToRgba(MapColor(Colormap::kTurbo, rp.points[i].depth_m / 20.0)));
      }
      gl_->camera_points.Upload(positions, colors);
      gl_->camera_points.Draw(gfx::Matrix4f::Identity(), static_cast<float>(view.point_size_px),
                              static_cast<float>(view.point_opacity));
    }
  }
  ImGui::Image(TextureId(gl_->camera_target.color_texture()), ImVec2(tw, th), ImVec2(0, 1),
               ImVec2(1, 0));
  const bool hovered = ImGui::IsItemHovered();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, ImVec2(origin.x + tw, origin.y + th), true);
  if (pair->detection)
    for (const Vec2& corner : pair->detection->pixels)
      if (const auto px = shown_pixel(corner))
        draw->AddCircle(to_screen(*px), 3.0f, IM_COL32(255, 220, 0, 255));
  if (pair->camera) {
    // Sheet outline (edges subdivided: lenses bend them) and board axes.
    const BoardSpec& board = s.dataset->target;
    const double hw = board.SheetWidth() / 2, hh = board.SheetHeight() / 2;
    const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
    std::vector<ImVec2> outline;
    for (int e = 0; e < 4; ++e)
      for (int k = 0; k < 16; ++k) {
        const Vec3 p = corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 16.0);
        if (const auto px = shown.Project(pair->camera->cam_from_board * p))
          outline.push_back(to_screen(*px));
      }
    if (outline.size() > 2)
      draw->AddPolyline(outline.data(), static_cast<int>(outline.size()),
                        IM_COL32(80, 200, 255, 255), ImDrawFlags_Closed, 2.0f);
    const double axis = 0.5 * std::min(hw, hh);
    const auto o = shown.Project(pair->camera->cam_from_board * Vec3::Zero());
    const ImU32 axis_colors[3] = {IM_COL32(255, 60, 60, 255), IM_COL32(60, 255, 60, 255),
                                  IM_COL32(80, 120, 255, 255)};
    for (int a = 0; a < 3 && o; ++a) {
      const Vec3 tip = pair->camera->cam_from_board * (Vec3::Unit(a) * (a == 2 ? -axis : axis));
      if (const auto px = shown.Project(tip))
        draw->AddLine(to_screen(*o), to_screen(*px), axis_colors[a], 2.0f);
    }
  } else {
    draw->AddText(ImVec2(origin.x + 12, origin.y + 12), IM_COL32(255, 90, 80, 255),
                  ("board not found: " + pair->camera_failure).c_str());
  }
  draw->PopClipRect();
  if (hovered) {
    const ImGuiIO& io = ImGui::GetIO();
    if (io.MouseWheel != 0) {
      // Zoom about the pixel under the mouse.
      const float mx = u0 + (io.MousePos.x - origin.x) / tw * span;
      const float my = v0 + (io.MousePos.y - origin.y) / th * span;
      camera_zoom_ = std::clamp(camera_zoom_ * std::pow(1.25f, io.MouseWheel), 1.0f, 32.0f);
      const float new_span = 1.0f / camera_zoom_;
      camera_center_x_ = mx - (io.MousePos.x - origin.x) / tw * new_span + new_span / 2;
      camera_center_y_ = my - (io.MousePos.y - origin.y) / th * new_span + new_span / 2;
    }
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
      camera_center_x_ -= io.MouseDelta.x / tw * span;
      camera_center_y_ -= io.MouseDelta.y / th * span;
    }
    if (!s.solver.result)
      ImGui::SetTooltip("run the solver to project the LiDAR points into this image");
  }
  ImGui::End();
}

void Workbench::DrawScene(const Snapshot& s, const PairView& pair,
                          const gfx::Matrix4f& view_projection, const Pose* estimate, int tw,
                          int th) {
  const LidarCloud& cloud = *pair.cloud;
  const ViewState& v = s.view;
  // Lines: ground grid, LiDAR axes, camera axes at the displayed estimate.
  std::vector<Eigen::Vector3f> lines;
  std::vector<gfx::Rgba> line_colors;
  auto add_line = [&](const Vec3& a, const Vec3& b, gfx::Rgba c) {
    lines.push_back(a.cast<float>());
    lines.push_back(b.cast<float>());
    line_colors.push_back(c);
    line_colors.push_back(c);
  };
  const double floor_z = gl_->scene_floor_z;
  for (int k = -10; k <= 10; ++k) {
    const gfx::Rgba grid{70, 70, 78, 255};
    add_line({k * 1.0, -10, floor_z}, {k * 1.0, 10, floor_z}, grid);
    add_line({-10, k * 1.0, floor_z}, {10, k * 1.0, floor_z}, grid);
  }
  auto add_axes = [&](const Pose& world_from_frame, double length) {
    const gfx::Rgba colors[3] = {{255, 60, 60, 255}, {60, 230, 60, 255}, {80, 120, 255, 255}};
    for (int a = 0; a < 3; ++a)
      add_line(world_from_frame.translation(), world_from_frame * (Vec3::Unit(a) * length),
               colors[a]);
  };
  add_axes(Pose::Identity(), 0.5);
  std::vector<Eigen::Vector3f> quads;
  std::vector<gfx::Rgba> quad_colors;
  auto add_quad = [&](const Vec3(&c)[4], gfx::Rgba color) {
    for (int k : {0, 1, 2, 0, 2, 3}) {
      quads.push_back(c[k].cast<float>());
      quad_colors.push_back(color);
    }
  };
  if (pair.lidar) {
    // The LiDAR board: the inliers' extent in the fitted plane.
    const Vec3 n = pair.lidar->plane.normal;
    Vec3 centroid = Vec3::Zero();
    for (int i : pair.lidar->inliers) centroid += cloud.points[i].cast<double>();
    centroid /= std::max<size_t>(1, pair.lidar->inliers.size());
    const Vec3 u = n.unitOrthogonal(), w = n.cross(u);
    double u0 = 1e9, u1 = -1e9, w0 = 1e9, w1 = -1e9;
    for (int i : pair.lidar->inliers) {
      const Vec3 d = cloud.points[i].cast<double>() - centroid;
      u0 = std::min(u0, d.dot(u)), u1 = std::max(u1, d.dot(u));
      w0 = std::min(w0, d.dot(w)), w1 = std::max(w1, d.dot(w));
    }
    const Vec3 c[4] = {centroid + u0 * u + w0 * w, centroid + u1 * u + w0 * w,
                       centroid + u1 * u + w1 * w, centroid + u0 * u + w1 * w};
    add_quad(c, {60, 140, 255, 110});
  }
  if (estimate) {
    const Pose lidar_from_cam = estimate->inverse();
    add_axes(lidar_from_cam, 0.3);
    if (pair.camera) {
      const BoardSpec& board = s.dataset->target;
      const double hw = board.SheetWidth() / 2, hh = board.SheetHeight() / 2;
      const Pose lidar_from_board = lidar_from_cam * pair.camera->cam_from_board;
      const Vec3 c[4] = {lidar_from_board * Vec3(-hw, -hh, 0), lidar_from_board * Vec3(hw, -hh, 0),
                         lidar_from_board * Vec3(hw, hh, 0), lidar_from_board * Vec3(-hw, hh, 0)};
      add_quad(c, {255, 150, 40, 110});
    }
  }
  gl_->scene_target.Resize(tw, th);
  gl_->scene_target.Bind();
  gl_->scene_target.Clear(0.08f, 0.08f, 0.1f, 1.0f);
  gl_->scene_lines.Upload(lines, line_colors);
  gl_->scene_lines.Draw(view_projection);
  gl_->scene_points.Draw(view_projection, static_cast<float>(v.point_size_px));
  gl_->scene_quads.Upload(quads, quad_colors);
  gl_->scene_quads.Draw(view_projection);
}

void Workbench::SceneView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents) {
  if (!BeginView("3D", r.x, r.y, r.w, r.h)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  if (!pair || !pair->cloud || !s.dataset) {
    ImGui::TextDisabled("loading ...");
    return ImGui::End();
  }
  static const char* kColorings[] = {"intensity", "range", "ring"};
  const int coloring = static_cast<int>(s.view.lidar_channel);
  const bool can_use_camera =
      s.reprojection && s.reprojection->pair_id == pair->id && s.selected_image && s.solver.result;
  ImGui::Checkbox("camera colours", &scene_camera_colors_);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("colour the cloud from the camera image (after a solve)");
  ImGui::SameLine();
  ImGui::TextDisabled(
      "else %s (LiDAR view); magenta: plane inliers. drag: orbit, right: pan, wheel: zoom",
      kColorings[coloring]);
  const bool camera_colors = scene_camera_colors_ && can_use_camera;
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int tw = std::max(1, static_cast<int>(avail.x)),
            th = std::max(1, static_cast<int>(avail.y));
  const LidarCloud& cloud = *pair->cloud;
  const std::uint64_t key =
      reinterpret_cast<std::uintptr_t>(&cloud) ^ (static_cast<std::uint64_t>(coloring) << 56) ^
      (camera_colors ? reinterpret_cast<std::uintptr_t>(s.reprojection.get()) << 3 : 0) ^
      ((pair->lidar ? pair->lidar->inliers.size() + 1 : 0) << 36);
  if (key != scene_key_) {
    scene_key_ = key;
    std::vector<gfx::Rgba> colors(cloud.size());
    if (camera_colors) {
      const CloudColors from_image =
          ColorizeCloud(s.dataset->camera, s.solver.result->cam_from_lidar, cloud,
                        *s.selected_image, s.reprojection->visible, s.reprojection->points);
      for (size_t i = 0; i < cloud.size(); ++i)
        colors[i] = from_image.has_color[i]
                        ? gfx::Rgba{from_image.bgr[3 * i + 2], from_image.bgr[3 * i + 1],
                                    from_image.bgr[3 * i], 255}
                        : gfx::Rgba{70, 70, 76, 255};
    } else {
      std::vector<float> values(cloud.size());
      for (size_t i = 0; i < cloud.size(); ++i) {
        if (coloring == 0)
          values[i] = cloud.HasIntensity() ? cloud.intensity[i] : cloud.points[i].norm();
        else if (coloring == 1)
          values[i] = cloud.points[i].norm();
        else
          values[i] = cloud.HasRing() ? static_cast<float>(cloud.ring[i]) : cloud.points[i].z();
      }
      std::vector<float> sorted = values;
      std::sort(sorted.begin(), sorted.end());
      const float lo = sorted.empty() ? 0 : sorted[sorted.size() / 50];
      const float hi = sorted.empty() ? 1 : sorted[sorted.size() - 1 - sorted.size() / 50];
      for (size_t i = 0; i < cloud.size(); ++i)
        colors[i] = ToRgba(MapColor(Colormap::kTurbo, (values[i] - lo) / std::max(1e-6f, hi - lo)));
    }
    if (pair->lidar)
      for (int i : pair->lidar->inliers) colors[i] = {255, 40, 220, 255};
    gl_->scene_points.Upload(cloud.points, colors);
    // The grid goes on the floor: a low percentile of the heights, robust to a few stray returns.
    std::vector<float> heights(cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) heights[i] = cloud.points[i].z();
    if (!heights.empty()) {
      std::nth_element(heights.begin(), heights.begin() + heights.size() / 50, heights.end());
      gl_->scene_floor_z = heights[heights.size() / 50];
    }
  }
  // Orbit camera about the target (LiDAR frame, z up).
  const ViewState& v = s.view;
  const Eigen::Vector3f target(static_cast<float>(v.orbit_target[0]),
                               static_cast<float>(v.orbit_target[1]),
                               static_cast<float>(v.orbit_target[2]));
  const Eigen::Vector3f forward(
      static_cast<float>(std::cos(v.orbit_pitch_rad) * std::cos(v.orbit_yaw_rad)),
      static_cast<float>(std::cos(v.orbit_pitch_rad) * std::sin(v.orbit_yaw_rad)),
      static_cast<float>(-std::sin(v.orbit_pitch_rad)));
  const Eigen::Vector3f eye = target - static_cast<float>(v.orbit_distance_m) * forward;
  const gfx::Matrix4f view_projection =
      gfx::Perspective(0.9f, static_cast<float>(tw) / th, 0.05f, 500.0f) *
      gfx::LookAt(eye, target, Eigen::Vector3f::UnitZ());
  const Pose* estimate = DisplayedEstimate(s);

  // Redraw only when something shown changed: the cloud and its colours, the view, the point
  // size or the estimate (131k points on llvmpipe cost most of a frame).
  std::uint64_t frame_key = scene_key_ ^ 0xcbf29ce484222325ull;
  auto mix = [&frame_key](const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) frame_key = (frame_key ^ p[i]) * 0x100000001b3ull;
  };
  mix(view_projection.data(), sizeof(float) * 16);
  mix(&v.point_size_px, sizeof(double));
  if (estimate) mix(estimate->matrix().data(), sizeof(double) * 16);
  if (frame_key != scene_frame_key_ || gl_->scene_target.width() != tw ||
      gl_->scene_target.height() != th) {
    scene_frame_key_ = frame_key;
    DrawScene(s, *pair, view_projection, estimate, tw, th);
  }
  ImGui::Image(TextureId(gl_->scene_target.color_texture()), ImVec2(tw, th), ImVec2(0, 1),
               ImVec2(1, 0));
  if (ImGui::IsItemHovered()) {
    const ImGuiIO& io = ImGui::GetIO();
    ViewState next = v;
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      next.orbit_yaw_rad -= io.MouseDelta.x * 0.01;
      next.orbit_pitch_rad = std::clamp(next.orbit_pitch_rad + io.MouseDelta.y * 0.01, -1.5, 1.5);
    }
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
      const double k = v.orbit_distance_m * 0.002;
      const Vec3 right(-std::sin(v.orbit_yaw_rad), std::cos(v.orbit_yaw_rad), 0);
      for (int a = 0; a < 3; ++a) next.orbit_target[a] -= k * io.MouseDelta.x * -right[a];
      next.orbit_target[2] += k * io.MouseDelta.y;
    }
    if (io.MouseWheel != 0)
      next.orbit_distance_m =
          std::clamp(v.orbit_distance_m * std::pow(0.85, io.MouseWheel), 0.5, 200.0);
    if (!(next == v)) intents->push_back(SetView{next});
  }
  ImGui::End();
}

}  // namespace calibench::ui
