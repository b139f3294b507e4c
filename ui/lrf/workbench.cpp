#include "ui/lrf/workbench.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geometry/geometry.h"
#include "core/lrf/result_io.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/renderers.h"
#include "ui/gfx/scene_layers.h"
#include "ui/lrf/workbench_draw.h"
#include "ui/widgets/frame_key.h"
#include "ui/widgets/layer_toggles.h"
#include "ui/widgets/pair_review.h"
#include "ui/widgets/path_field.h"
#include "ui/widgets/solution_readouts.h"
#include "ui/widgets/workbench_layout.h"

namespace calibench::ui {

struct LrfWorkbench::Gl {
  gfx::ImageTexture picture;  // depth picture or RGB image of the selected pair
  gfx::Framebuffer scene_target;
  gfx::PointRenderer cloud_points, scan_points;
  gfx::SceneLayers scene_layers;       // grid, frames, depth cloud, scan, board (DrawScene)
  const void* cloud_source = nullptr;  // the features the cloud was built from
  Vec3 scene_center = Vec3(0, 0, 2);   // orbit target, camera frame (metres)
  double floor_y = 1.0;                // camera y of the grid (y down), metres
};

namespace lrf_view {

const LrfPairFeatures* SelectedFeatures(const LrfSnapshot& s) {
  if (s.selected < 0 || s.selected >= static_cast<int>(s.pairs.size())) return nullptr;
  return s.pairs[s.selected].features.get();
}

// Begins a view of the selected pair: its features, or nullptr after saying what the view waits
// for. Call ImGui::End() either way.
const LrfPairFeatures* BeginPairView(const char* title, const LrfSnapshot& s, const Rect& r) {
  if (!BeginView(title, r)) return nullptr;
  const LrfPairFeatures* pair = SelectedFeatures(s);
  if (pair) return pair;
  if (!s.dataset)
    ImGui::TextDisabled("no dataset open");
  else
    ImGui::TextDisabled("extracting features: %d / %d pairs ...", s.extracted_done,
                        s.extracted_total);
  return nullptr;
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

}  // namespace lrf_view

using namespace lrf_view;

namespace {

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
  if (x.z() < 0.05) return std::nullopt;  // nearer than any depth camera sees
  return dataset.depth_camera.Project(x);
}

Vec3 OnScanPlane(const Vec2& p) { return Vec3(p.x(), p.y(), 0.0); }

// ---- The image view: the depth picture (three-face) or the camera image (checkerboard).

// What the image shows of the pair, in words; the picture's source (the camera image, or the
// pair for its depth frame), nullptr when there is none.
const void* ImageReadouts(const LrfSnapshot& s, const LrfPairFeatures& pair, bool board_case) {
  if (board_case) {
    if (pair.camera)
      ImGui::Text("board: %d corners, reprojection RMS %.2f px, %.2f m away",
                  pair.camera->num_corners, pair.camera->reprojection_rms_px,
                  pair.camera->plane.distance);
    else
      ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "board not found: %s", pair.reason.c_str());
    return s.selected_image.get();
  }
  if (!pair.three_face) return nullptr;
  const DepthFeatures& d = pair.three_face->depth;
  if (d.ok)
    ImGui::Text("faces %d / %d / %d px, plane RMS %.1f mm, smallest angle %.0f deg",
                d.inlier_counts[0], d.inlier_counts[1], d.inlier_counts[2], d.rms_m * 1e3,
                d.min_face_angle_deg);
  else
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no faces: %s", d.reason.c_str());
  return pair.depth ? &pair : nullptr;
}

// The checkerboard sheet's outline, edges subdivided (lenses bend them).
void DrawSheetOutline(ImDrawList* draw, const LrfDataset& dataset, const Pose& cam_from_board,
                      const ZoomPanImage::Placement& at) {
  const double hw = dataset.board.SheetWidth() / 2, hh = dataset.board.SheetHeight() / 2;
  const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
  std::vector<ImVec2> outline;
  for (int e = 0; e < 4; ++e)
    for (int k = 0; k < 16; ++k)
      if (const auto px = ProjectToImage(
              dataset,
              cam_from_board * (corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 16.0))))
        outline.push_back(at.ToScreen(*px));
  if (outline.size() > 2)
    draw->AddPolyline(outline.data(), static_cast<int>(outline.size()), IM_COL32(80, 200, 255, 255),
                      ImDrawFlags_Closed, 2.0f);
}

// Every return moved into the camera by the estimate, the target's larger and outlined, and the
// corners F G H.
void DrawScanInImage(ImDrawList* draw, const LrfDataset& dataset, const LrfPairFeatures& pair,
                     const Pose& estimate, const ZoomPanImage::Placement& at) {
  const LaserScan& scan = pair.scan;
  for (size_t i = 0; i < scan.ranges.size(); ++i)
    if (scan.Valid(i))
      if (const auto px = ProjectToImage(dataset, estimate * OnScanPlane(scan.Point(i))))
        draw->AddCircleFilled(at.ToScreen(*px), 1.5f, kScanInCamera, 6);
  // Outlines first, then the fills: the target's returns are dense.
  std::vector<ImVec2> on_target;
  for (const auto& [p, face] : TargetPoints(pair))
    if (const auto px = ProjectToImage(dataset, estimate * OnScanPlane(p)))
      on_target.push_back(at.ToScreen(*px));
  for (const ImVec2& q : on_target) draw->AddCircleFilled(q, 3.2f, IM_COL32(0, 0, 0, 255), 8);
  for (const ImVec2& q : on_target) draw->AddCircleFilled(q, 2.0f, kScanInCamera, 8);
  if (!pair.three_face || !pair.three_face->scan.ok) return;
  for (int c = 0; c < 3; ++c)
    if (const auto px =
            ProjectToImage(dataset, estimate * OnScanPlane(pair.three_face->scan.corners[c])))
      DrawCornerRing(draw, at.ToScreen(*px), c);
}

// ---- The 3D view, in the camera frame.

// The depth frame back-projected (every stride-th pixel, at most ~40k points), faces coloured,
// the rest grey by distance.
struct DepthCloud {
  std::vector<Eigen::Vector3f> positions;
  std::vector<gfx::Rgba> colors;
  Vec3 face_sum = Vec3::Zero(), all_sum = Vec3::Zero();
  int face_count = 0;
  std::vector<double> heights;  // camera y of each point
};

DepthCloud BackProject(const LrfPairFeatures& pair) {
  DepthCloud cloud;
  if (!pair.depth) return cloud;
  const DepthImage& depth = *pair.depth;
  const DepthIntrinsics& k = depth.intrinsics;
  const auto* faces =
      pair.three_face && pair.three_face->depth.face_of_pixel.size() == depth.depth_m.size()
          ? &pair.three_face->depth.face_of_pixel
          : nullptr;
  const int stride =
      std::max(1, static_cast<int>(std::ceil(std::sqrt(k.width * k.height / 40000.0))));
  for (int v = 0; v < k.height; v += stride)
    for (int u = 0; u < k.width; u += stride) {
      const double z = depth.At(u, v);
      if (z <= 0) continue;
      const Vec3 x = k.Unproject(Vec2(static_cast<double>(u), static_cast<double>(v)), z);
      const int face = faces ? (*faces)[static_cast<size_t>(v) * k.width + u] : -1;
      cloud.positions.push_back(x.cast<float>());
      cloud.all_sum += x;
      cloud.heights.push_back(x.y());
      if (face >= 0 && face < 3) {
        cloud.colors.push_back({kFaceRgb[face][0], kFaceRgb[face][1], kFaceRgb[face][2], 255});
        cloud.face_sum += x;
        ++cloud.face_count;
      } else {
        const auto g = static_cast<std::uint8_t>(std::clamp(190.0 - 15.0 * z, 90.0, 190.0));
        cloud.colors.push_back({g, g, g, 255});
      }
    }
  return cloud;
}

// `text` next to the camera-frame point x, when it is in front of the camera and in the view.
void LabelAt(const gfx::Matrix4f& view_projection, ImVec2 origin, ImVec2 size, const Vec3& x,
             const char* text) {
  const Eigen::Vector4f clip = view_projection * Eigen::Vector4f(x.x(), x.y(), x.z(), 1.0f);
  if (clip.w() <= 0) return;
  const float u = (clip.x() / clip.w() + 1) / 2, v = (1 - clip.y() / clip.w()) / 2;
  if (u < 0 || u > 1 || v < 0 || v > 1) return;
  ImGui::GetWindowDrawList()->AddText({origin.x + u * size.x + 4, origin.y + v * size.y + 2},
                                      IM_COL32(220, 220, 220, 255), text);
}

}  // namespace

bool ParseLrfLayout(const std::string& name, LrfLayout* layout) {
  return ParseLayoutName(name, {"workbench", "scan", "depth", "3d"}, layout);
}

LrfWorkbench::LrfWorkbench()
    : WorkbenchFrame(LoadLayoutShares("lrf", {0.58f, 0.5f})), gl_(std::make_unique<Gl>()) {}

LrfWorkbench::~LrfWorkbench() = default;

void LrfWorkbench::View(int index, const LrfSnapshot& s, const Rect& r,
                        std::vector<LrfIntent>* /*intents: the views return none*/) {
  if (index == 0) ScanView(s, r);
  if (index == 1) ImageView(s, r);
  if (index == 2) SceneView(s, r);
}

std::string LrfWorkbench::Opened(const LrfSnapshot& s) const {
  return "dataset: " + s.manifest.filename().string();
}

const Pose* LrfWorkbench::DisplayedEstimate(const LrfSnapshot& s) const {
  return replay().ShownEstimate(s.solver.iterations,
                                s.solver.solution ? &s.solver.solution->cam_from_lrf : nullptr);
}

void LrfWorkbench::ImageView(const LrfSnapshot& s, const Rect& r) {
  const bool board_case = s.dataset && s.dataset->target_type == LrfTargetType::kCheckerboard;
  const LrfPairFeatures* pair = BeginPairView(board_case ? "Camera image" : "Depth image", s, r);
  if (!pair) return ImGui::End();
  const void* source = ImageReadouts(s, *pair, board_case);
  const Pose* estimate = DisplayedEstimate(s);
  ImGui::TextDisabled(estimate ? "yellow: the scan moved into the camera; rings: F G H"
                               : "run the solver to project the scan into this image");
  if (!source) {
    ImGui::TextDisabled(board_case ? "loading image ..." : "no depth frame: %s",
                        pair->reason.c_str());
    return ImGui::End();
  }
  UploadPicture(s, *pair, source);
  const ZoomPanImage::Placement at = image_.Place(gl_->picture.width(), gl_->picture.height());
  ZoomPanImage::Show(at, gl_->picture.texture());
  const bool hovered = ImGui::IsItemHovered();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(at.origin, ImVec2(at.origin.x + at.size.x, at.origin.y + at.size.y), true);
  if (board_case && pair->camera)
    DrawSheetOutline(draw, *s.dataset, pair->camera->cam_from_board, at);
  if (estimate) DrawScanInImage(draw, *s.dataset, *pair, *estimate, at);
  draw->PopClipRect();
  if (hovered) image_.HandleMouse(at);
  ImGui::End();
}

void LrfWorkbench::UploadPicture(const LrfSnapshot& s, const LrfPairFeatures& pair,
                                 const void* source) {
  if (reinterpret_cast<std::uintptr_t>(source) == image_key_) return;
  image_key_ = reinterpret_cast<std::uintptr_t>(source);
  if (source == s.selected_image.get())
    gl_->picture.Upload(*s.selected_image, true);
  else
    gl_->picture.Upload(ComposeDepthPicture(*pair.depth, pair.three_face->depth), false);
}

void LrfWorkbench::UploadDepthCloud(const LrfPairFeatures& pair) {
  if (gl_->cloud_source == &pair) return;
  gl_->cloud_source = &pair;
  DepthCloud cloud = BackProject(pair);
  gl_->cloud_points.Upload(cloud.positions, cloud.colors);
  // Orbit about the target's faces, else the board, else the whole cloud.
  if (cloud.face_count)
    gl_->scene_center = cloud.face_sum / cloud.face_count;
  else if (pair.camera)
    gl_->scene_center = pair.camera->cam_from_board.translation();
  else if (!cloud.positions.empty())
    gl_->scene_center = cloud.all_sum / static_cast<double>(cloud.positions.size());
  // The grid goes on the floor: a high percentile of the heights (y down).
  std::vector<double>& heights = cloud.heights;
  if (!heights.empty()) {
    std::nth_element(heights.begin(), heights.begin() + heights.size() * 49 / 50, heights.end());
    gl_->floor_y = heights[heights.size() * 49 / 50];
  } else {
    gl_->floor_y = gl_->scene_center.y() + 1.0;
  }
}

void LrfWorkbench::DrawScene(const LrfSnapshot& s, const LrfPairFeatures& pair,
                             const gfx::Matrix4f& view_projection, const Pose* estimate, int tw,
                             int th) {
  gfx::SceneLayers& layers = gl_->scene_layers;
  layers.Clear();
  // A 0.5 m grid on the floor (camera y points down), around and behind the target.
  gfx::LineBatch& grid = layers["grid"].lines;
  const Vec3& c = gl_->scene_center;
  const double x0 = std::round(c.x()) - 4, z1 = std::ceil(c.z()) + 3, y = gl_->floor_y;
  const gfx::Rgba color{62, 62, 70, 255};
  for (int k = 0; k <= 16; ++k) grid.Add({x0 + 0.5 * k, y, 0}, {x0 + 0.5 * k, y, z1}, color);
  for (int k = 0; k <= 2 * z1; ++k) grid.Add({x0, y, 0.5 * k}, {x0 + 8, y, 0.5 * k}, color);
  gfx::LineBatch& frames = layers["frames"].lines;
  frames.AddAxes(Pose::Identity(), 0.3);         // the camera
  if (estimate) frames.AddAxes(*estimate, 0.3);  // the LRF at the estimate
  layers["depth cloud"].points = &gl_->cloud_points;
  std::vector<Eigen::Vector3f> scan;
  if (estimate)
    for (size_t i = 0; i < pair.scan.ranges.size(); ++i)
      if (pair.scan.Valid(i) && pair.scan.ranges[i] < 15.0)
        scan.push_back((*estimate * OnScanPlane(pair.scan.Point(i))).cast<float>());
  gl_->scan_points.Upload(scan, std::vector<gfx::Rgba>(scan.size(), gfx::Rgba{255, 225, 40, 255}));
  gfx::SceneLayers::Layer& scan_layer = layers["scan"];
  scan_layer.points = &gl_->scan_points;
  scan_layer.point_size_px = 4.0f;
  if (pair.camera)
    layers["board"].triangles.AddRectangle(pair.camera->cam_from_board,
                                           s.dataset->board.SheetWidth(),
                                           s.dataset->board.SheetHeight(), {255, 150, 40, 110});
  gl_->scene_target.Resize(tw, th);
  gl_->scene_target.Clear(0.08f, 0.08f, 0.1f, 1.0f);
  layers.Draw(view_projection);
}

void LrfWorkbench::SceneView(const LrfSnapshot& s, const Rect& r) {
  const LrfPairFeatures* pair = BeginPairView("3D (camera frame)", s, r);
  if (!pair) return ImGui::End();
  const Pose* estimate = DisplayedEstimate(s);
  LayerToggles(&gl_->scene_layers);
  ImGui::SameLine();
  ImGui::TextDisabled(estimate ? "cloud by face; yellow: the scan at the estimate. drag: orbit, "
                                 "wheel: zoom"
                               : "cloud by face; run the solver to move the scan in. drag: orbit");
  UploadDepthCloud(*pair);
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int tw = std::max(1, static_cast<int>(avail.x)),
            th = std::max(1, static_cast<int>(avail.y));
  // Orbit about a point between the camera and the target, so that both stay in view.
  const Vec3& center = gl_->scene_center;
  const gfx::Matrix4f view_projection =
      orbit_.ViewProjection((0.65 * center).cast<float>(),
                            orbit_.distance * std::max(0.5f, static_cast<float>(center.norm())),
                            static_cast<float>(tw) / th, 200.0f, WorldUp::kYDown);
  // Redraw only when something shown changed: the pair, the view or the estimate.
  FrameKey key(reinterpret_cast<std::uintptr_t>(pair));
  key.Mix(view_projection.data(), sizeof(float) * 16);
  if (estimate) key.Mix(estimate->matrix().data(), sizeof(double) * 16);
  const std::uint64_t shown_layers = gl_->scene_layers.VisibilityKey();
  key.Mix(&shown_layers, sizeof(shown_layers));
  if (key.value() != scene_key_ || gl_->scene_target.width() != tw ||
      gl_->scene_target.height() != th) {
    scene_key_ = key.value();
    DrawScene(s, *pair, view_projection, estimate, tw, th);
  }
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  FramebufferImage(gl_->scene_target, ImVec2(tw, th));
  // Frame names next to their axes.
  LabelAt(view_projection, origin, ImVec2(tw, th), Vec3::Zero(), "camera");
  if (estimate) LabelAt(view_projection, origin, ImVec2(tw, th), estimate->translation(), "LRF");
  if (ImGui::IsItemHovered()) orbit_.HandleMouse(/*drag_turns_right=*/true, 0.2f, 20.0f);
  ImGui::End();
}

}  // namespace calibench::ui
