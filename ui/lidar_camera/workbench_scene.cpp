// The 3D view of the workbench: the LiDAR cloud (coloured by a LiDAR channel, or from the camera
// image after a solve), the board planes and both sensor frames, in the LiDAR frame.
#include <imgui.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/lidar/colormap.h"
#include "core/reproject/reproject.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/frame_key.h"
#include "ui/widgets/layer_toggles.h"
#include "ui/widgets/orbit_camera.h"

namespace calibench::ui {
namespace {

// The cloud coloured from the camera image at the solution; grey where the camera sees nothing.
std::vector<gfx::Rgba> ImageColors(const Snapshot& s, const LidarCloud& cloud) {
  std::vector<gfx::Rgba> colors(cloud.size());
  const CloudColors from_image =
      ColorizeCloud(s.dataset->camera, s.solver.result->cam_from_lidar, cloud, *s.selected_image,
                    s.reprojection->visible, s.reprojection->points);
  for (size_t i = 0; i < cloud.size(); ++i)
    colors[i] = from_image.has_color[i]
                    ? gfx::Rgba{from_image.bgr[3 * i + 2], from_image.bgr[3 * i + 1],
                                from_image.bgr[3 * i], 255}
                    : gfx::Rgba{70, 70, 76, 255};
  return colors;
}

// The cloud coloured by a LiDAR channel (0 intensity, 1 range, 2 ring), the 2nd to 98th
// percentile spread over the colour map.
std::vector<gfx::Rgba> ChannelColors(const LidarCloud& cloud, int channel) {
  std::vector<float> values(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (channel == 0)
      values[i] = cloud.HasIntensity() ? cloud.intensity[i] : cloud.points[i].norm();
    else if (channel == 1)
      values[i] = cloud.points[i].norm();
    else
      values[i] = cloud.HasRing() ? static_cast<float>(cloud.ring[i]) : cloud.points[i].z();
  }
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const float lo = sorted.empty() ? 0 : sorted[sorted.size() / 50];
  const float hi = sorted.empty() ? 1 : sorted[sorted.size() - 1 - sorted.size() / 50];
  std::vector<gfx::Rgba> colors(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i)
    colors[i] = ToRgba(MapColor(Colormap::kTurbo, (values[i] - lo) / std::max(1e-6f, hi - lo)));
  return colors;
}

// The LiDAR board: the inliers' extent in the fitted plane, as a rectangle's corners.
std::array<Vec3, 4> InlierExtent(const LidarCloud& cloud, const LidarPlaneFit& fit) {
  const Vec3 n = fit.plane.normal;
  const Vec3& centroid = fit.inlier_centroid;
  const Vec3 u = n.unitOrthogonal(), w = n.cross(u);
  double u0 = 1e9, u1 = -1e9, w0 = 1e9, w1 = -1e9;
  for (int i : fit.inliers) {
    const Vec3 d = cloud.points[i].cast<double>() - centroid;
    u0 = std::min(u0, d.dot(u)), u1 = std::max(u1, d.dot(u));
    w0 = std::min(w0, d.dot(w)), w1 = std::max(w1, d.dot(w));
  }
  return {centroid + u0 * u + w0 * w, centroid + u1 * u + w0 * w, centroid + u1 * u + w1 * w,
          centroid + u0 * u + w1 * w};
}

// "camera colours", the brush, and what the view shows otherwise; the mouse's use.
void SceneToolbar(const Snapshot& s, bool* camera_colors, bool* brush, gfx::SceneLayers* layers,
                  std::vector<Intent>* intents) {
  static const char* kColorings[] = {"intensity", "range", "ring"};
  if (ImGui::SmallButton("frame [F]")) intents->push_back(FrameView{});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("turn the view onto this pair's board (its cloud before the board is found)");
  ImGui::SameLine();
  LayerToggles(layers);
  ImGui::SameLine();
  ImGui::Checkbox("camera colours", camera_colors);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("colour the cloud from the camera image (after a solve)");
  ImGui::SameLine();
  ImGui::Checkbox("brush", brush);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "left drag paints the board on the points (shift erases); the same brush "
        "as the LiDAR image's");
  ImGui::SameLine();
  ImGui::TextDisabled(
      "else %s; magenta: plane inliers (cyan: detected). %s, right: pan, wheel: zoom",
      kColorings[static_cast<int>(s.view.lidar_channel)], *brush ? "drag: paint" : "drag: orbit");
}

// The screen radius of the 3D brush: the LiDAR image brush's radius, scaled so that the default
// covers a few rings of a board at 2-3 m.
float SceneBrushRadiusPx(const ViewState& view) {
  return static_cast<float>(4.0 * view.brush_radius_px);
}

// The LiDAR-image pixels of the points under a circle of the 3D view: those that project within
// radius_px of `centre` (screen pixels; the view drawn at `origin`, w x h) and lie on the nearest
// surface there (within 0.3 m of the nearest such point's depth), so that a stroke on the board
// does not take the wall behind it. Sorted, unique.
std::vector<int> PixelsUnderSceneBrush(const PairView& pair, const gfx::Matrix4f& view_projection,
                                       const ImVec2& origin, float w, float h, const ImVec2& centre,
                                       float radius_px) {
  const LidarCloud& cloud = *pair.cloud;
  std::vector<std::pair<float, int>> hits;  // (depth, point)
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector4f clip = view_projection * cloud.points[i].homogeneous();
    if (clip.w() <= 1e-6f) continue;
    const float x = origin.x + (clip.x() / clip.w() + 1.0f) * 0.5f * w;
    const float y = origin.y + (1.0f - clip.y() / clip.w()) * 0.5f * h;
    if (std::hypot(x - centre.x, y - centre.y) <= radius_px)
      hits.emplace_back(clip.w(), static_cast<int>(i));
  }
  std::vector<int> pixels;
  if (hits.empty()) return pixels;
  const float nearest = std::min_element(hits.begin(), hits.end())->first;
  for (const auto& [depth, point] : hits)
    if (depth < nearest + 0.3f && pair.lidar_image->pixel_of_point[point] >= 0)
      pixels.push_back(pair.lidar_image->pixel_of_point[point]);
  std::sort(pixels.begin(), pixels.end());
  pixels.erase(std::unique(pixels.begin(), pixels.end()), pixels.end());
  return pixels;
}

// Left drag orbits, right drag pans the target in the ground plane and up, the wheel zooms: the
// view state after this frame's mouse over the hovered view.
ViewState OrbitByMouse(const ViewState& v) {
  OrbitCamera<double> orbit{v.orbit_yaw_rad, v.orbit_pitch_rad, v.orbit_distance_m};
  orbit.HandleMouse(/*drag_turns_right=*/false, 0.5, 200.0);
  ViewState next = v;
  next.orbit_yaw_rad = orbit.yaw_rad;
  next.orbit_pitch_rad = orbit.pitch_rad;
  next.orbit_distance_m = orbit.distance;
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
    const ImGuiIO& io = ImGui::GetIO();
    const double k = v.orbit_distance_m * 0.002;
    const Vec3 right(-std::sin(v.orbit_yaw_rad), std::cos(v.orbit_yaw_rad), 0);
    for (int a = 0; a < 3; ++a) next.orbit_target[a] -= k * io.MouseDelta.x * -right[a];
    next.orbit_target[2] += k * io.MouseDelta.y;
  }
  return next;
}

}  // namespace

void Workbench::SceneView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (!BeginView("3D", r)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  if (!pair || !pair->cloud || !s.dataset) {
    ImGui::TextDisabled(s.dataset ? "loading ..." : "no dataset open");
    return ImGui::End();
  }
  const bool can_use_camera =
      s.reprojection && s.reprojection->pair_id == pair->id && s.selected_image && s.solver.result;
  SceneToolbar(s, &scene_camera_colors_, &scene_brush_, &gl_->scene_layers, intents);
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int tw = std::max(1, static_cast<int>(avail.x)),
            th = std::max(1, static_cast<int>(avail.y));
  UploadSceneCloud(s, *pair, scene_camera_colors_ && can_use_camera);
  // Orbit camera about the target (LiDAR frame, z up).
  const ViewState& v = s.view;
  const OrbitCamera<double> orbit{v.orbit_yaw_rad, v.orbit_pitch_rad, v.orbit_distance_m};
  const gfx::Matrix4f view_projection = orbit.ViewProjection(
      Eigen::Vector3d(v.orbit_target[0], v.orbit_target[1], v.orbit_target[2]).cast<float>(),
      static_cast<float>(v.orbit_distance_m), static_cast<float>(tw) / th, 500.0f, WorldUp::kZUp);
  const Pose* estimate = DisplayedEstimate(s);
  // Redraw only when something shown changed: the cloud and its colours, the view, the point
  // size or the estimate (131k points on llvmpipe cost most of a frame).
  FrameKey frame_key(scene_key_);
  frame_key.Mix(view_projection.data(), sizeof(float) * 16);
  frame_key.Mix(&v.point_size_px, sizeof(double));
  if (estimate) frame_key.Mix(estimate->matrix().data(), sizeof(double) * 16);
  if (s.next_pose && s.next_pose->lidar_from_board)
    frame_key.Mix(s.next_pose->lidar_from_board->matrix().data(), sizeof(double) * 16);
  const std::uint64_t shown_layers = gl_->scene_layers.VisibilityKey();
  frame_key.Mix(&shown_layers, sizeof(shown_layers));
  if (frame_key.value() != scene_frame_key_ || gl_->scene_target.width() != tw ||
      gl_->scene_target.height() != th) {
    scene_frame_key_ = frame_key.value();
    DrawScene(s, *pair, view_projection, estimate, tw, th);
  }
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  FramebufferImage(gl_->scene_target, ImVec2(tw, th));
  scene_image_rect_ = {origin.x, origin.y, static_cast<float>(tw), static_cast<float>(th)};
  if (scene_brush_ && ImGui::IsMouseReleased(ImGuiMouseButton_Left))
    intents->push_back(EndStroke{});
  if (ImGui::IsItemHovered()) {
    const ImGuiIO& io = ImGui::GetIO();
    if (scene_brush_ && pair->lidar_image) {
      const float radius = SceneBrushRadiusPx(v);
      ImGui::GetWindowDrawList()->AddCircle(
          io.MousePos, radius,
          io.KeyShift ? IM_COL32(255, 120, 90, 255) : IM_COL32(255, 255, 255, 220), 48, 1.5f);
      if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        std::vector<int> pixels =
            PixelsUnderSceneBrush(*pair, view_projection, origin, tw, th, io.MousePos, radius);
        if (!pixels.empty())
          intents->push_back(PaintPoints{s.selected, std::move(pixels), io.KeyShift});
      }
    }
    ViewState next = OrbitByMouse(v);
    if (scene_brush_) {  // the left drag paints: keep the orbit angles, allow pan and zoom
      next.orbit_yaw_rad = v.orbit_yaw_rad;
      next.orbit_pitch_rad = v.orbit_pitch_rad;
    }
    if (!(next == v)) intents->push_back(SetView{next});
  }
  ImGui::End();
}

// The cloud's colours (plane inliers magenta) into gl_->scene_points and the grid's height,
// when the cloud, the colouring or the inliers changed.
void Workbench::UploadSceneCloud(const Snapshot& s, const PairView& pair, bool camera_colors) {
  const LidarCloud& cloud = *pair.cloud;
  const int coloring = static_cast<int>(s.view.lidar_channel);
  const std::uint64_t key =
      reinterpret_cast<std::uintptr_t>(&cloud) ^ (static_cast<std::uint64_t>(coloring) << 56) ^
      (camera_colors ? reinterpret_cast<std::uintptr_t>(s.reprojection.get()) << 3 : 0) ^
      ((pair.lidar ? pair.lidar->inliers.size() + 1 : 0) << 36) ^
      (static_cast<std::uint64_t>(pair.brush_origin == BrushOrigin::kDetected) << 60);
  if (key == scene_key_) return;
  scene_key_ = key;
  std::vector<gfx::Rgba> colors =
      camera_colors ? ImageColors(s, cloud) : ChannelColors(cloud, coloring);
  const gfx::Rgba inlier = pair.brush_origin == BrushOrigin::kDetected
                               ? gfx::Rgba{40, 220, 255, 255}  // detected
                               : gfx::Rgba{255, 40, 220, 255};
  if (pair.lidar)
    for (int i : pair.lidar->inliers) colors[i] = inlier;
  gl_->scene_points.Upload(cloud.points, colors);
  // The grid goes on the floor: a low percentile of the heights, robust to a few stray returns.
  std::vector<float> heights(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) heights[i] = cloud.points[i].z();
  if (!heights.empty()) {
    std::nth_element(heights.begin(), heights.begin() + heights.size() / 50, heights.end());
    gl_->scene_floor_z = heights[heights.size() / 50];
  }
}

void Workbench::DrawScene(const Snapshot& s, const PairView& pair,
                          const gfx::Matrix4f& view_projection, const Pose* estimate, int tw,
                          int th) {
  const LidarCloud& cloud = *pair.cloud;
  gfx::SceneLayers& layers = gl_->scene_layers;
  layers.Clear();
  // The ground grid, the LiDAR's frame, its cloud and board; the camera's frame and board at the
  // displayed estimate; the ghost board (where to hold the board next).
  gfx::LineBatch& grid = layers["grid"].lines;
  const double floor_z = gl_->scene_floor_z;
  for (int k = -10; k <= 10; ++k) {
    const gfx::Rgba color{70, 70, 78, 255};
    grid.Add({k * 1.0, -10, floor_z}, {k * 1.0, 10, floor_z}, color);
    grid.Add({-10, k * 1.0, floor_z}, {10, k * 1.0, floor_z}, color);
  }
  layers["LiDAR frame"].lines.AddAxes(Pose::Identity(), 0.5);
  gfx::SceneLayers::Layer& points = layers["LiDAR points"];
  points.points = &gl_->scene_points;
  points.point_size_px = static_cast<float>(s.view.point_size_px);
  gfx::SceneLayers::Layer& lidar_board = layers["LiDAR board"];
  if (pair.lidar)
    lidar_board.triangles.AddQuad(InlierExtent(cloud, *pair.lidar), {60, 140, 255, 110});
  gfx::SceneLayers::Layer& camera = layers["camera"];
  // Every camera of the rig (one camera is a rig of one), the open one at the shown estimate.
  if (s.rig) DrawRigFrustums(s, estimate, &camera);
  if (estimate) {
    const Pose lidar_from_cam = estimate->inverse();
    camera.lines.AddAxes(lidar_from_cam, 0.3);
    if (pair.camera)
      camera.triangles.AddRectangle(lidar_from_cam * pair.camera->cam_from_board,
                                    s.dataset->target.SheetWidth(), s.dataset->target.SheetHeight(),
                                    {255, 150, 40, 110});
  }
  gfx::SceneLayers::Layer& ghost = layers["ghost board"];
  if (s.next_pose && s.next_pose->lidar_from_board) {
    const Pose& lidar_from_board = *s.next_pose->lidar_from_board;
    const double w = s.dataset->target.SheetWidth(), h = s.dataset->target.SheetHeight();
    ghost.triangles.AddRectangle(lidar_from_board, w, h, {120, 255, 140, 90});
    const gfx::Rgba edge{120, 255, 140, 255};
    const Vec3 corners[4] = {
        lidar_from_board * Vec3(-w / 2, -h / 2, 0), lidar_from_board * Vec3(w / 2, -h / 2, 0),
        lidar_from_board * Vec3(w / 2, h / 2, 0), lidar_from_board * Vec3(-w / 2, h / 2, 0)};
    for (int k = 0; k < 4; ++k) ghost.lines.Add(corners[k], corners[(k + 1) % 4], edge);
    // Its normal, from the sheet towards where the sensors are.
    ghost.lines.Add(lidar_from_board.translation(), lidar_from_board * Vec3(0, 0, 0.3), edge);
  }
  gl_->scene_target.Resize(tw, th);
  gl_->scene_target.Clear(0.08f, 0.08f, 0.1f, 1.0f);
  layers.Draw(view_projection);
}

}  // namespace calibench::ui
