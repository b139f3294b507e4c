// The LiDAR view of the workbench: the LiDAR image (intensity, range or ring) with the brush that
// marks the board, zoomed horizontally.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/lidar/colormap.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/toolbar.h"

namespace calibench::ui {
namespace {

// The LiDAR picture with the brush (white veil) and the plane inliers (magenta: no perceptual
// colour map uses it; cyan for a detected board) composed in.
ImageU8 ComposeLidarPicture(const PairView& pair, LidarChannel channel) {
  ImageU8 picture = RenderLidarImage(*pair.lidar_image, channel, Colormap::kTurbo);
  auto blend = [&](int pixel, int r, int g, int b, float alpha) {
    std::uint8_t* p = picture.data.data() + static_cast<size_t>(pixel) * picture.channels;
    p[0] = static_cast<std::uint8_t>(p[0] * (1 - alpha) + b * alpha);
    p[1] = static_cast<std::uint8_t>(p[1] * (1 - alpha) + g * alpha);
    p[2] = static_cast<std::uint8_t>(p[2] * (1 - alpha) + r * alpha);
  };
  // A detected board's region in cyan until the user edits it; a painted or seeded one in white.
  for (int pixel : pair.brush_pixels)
    pair.brush_origin == BrushOrigin::kDetected ? blend(pixel, 40, 220, 255, 0.55f)
                                                : blend(pixel, 255, 255, 255, 0.45f);
  // Inliers magenta, or cyan while the region is the detected one (not yet edited by the user).
  if (pair.lidar)
    for (int i : pair.lidar->inliers)
      if (pair.lidar_image->pixel_of_point[i] >= 0)
        pair.brush_origin == BrushOrigin::kDetected
            ? blend(pair.lidar_image->pixel_of_point[i], 40, 220, 255, 0.9f)
            : blend(pair.lidar_image->pixel_of_point[i], 255, 40, 220, 0.9f);
  return picture;
}

// The shares of the image's width (of 360 degrees) and of its rows the brush spans: the circle of
// its columns less the widest gap between them (a board may straddle the left/right seam), and
// its first to last row; zeros without a brush.
std::pair<double, double> BrushShares(const PairView& pair) {
  const LidarImage& image = *pair.lidar_image;
  if (pair.brush_pixels.empty() || image.columns <= 0 || image.rows <= 0) return {0.0, 0.0};
  std::vector<int> used;
  int first_row = image.rows, last_row = -1;
  for (int pixel : pair.brush_pixels) {
    used.push_back(pixel % image.columns);
    first_row = std::min(first_row, pixel / image.columns);
    last_row = std::max(last_row, pixel / image.columns);
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  int widest_gap = used.front() + image.columns - used.back();  // across the seam
  for (size_t i = 1; i < used.size(); ++i) widest_gap = std::max(widest_gap, used[i] - used[i - 1]);
  return {static_cast<double>(image.columns - widest_gap + 1) / image.columns,
          static_cast<double>(last_row - first_row + 1) / image.rows};
}

// What the composed picture depends on.
std::uint64_t LidarPictureKey(const PairView& pair, LidarChannel channel) {
  return reinterpret_cast<std::uintptr_t>(pair.lidar_image.get()) ^
         (pair.brush_pixels.size() * 2654435761ull) ^
         ((pair.lidar ? pair.lidar->inliers.size() + 1 : 0) << 20) ^
         (static_cast<std::uint64_t>(pair.brush_origin == BrushOrigin::kDetected) << 36) ^
         (static_cast<std::uint64_t>(channel) << 40);
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

void Workbench::LidarView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (!BeginView("LiDAR image", r)) return ImGui::End();
  const PairView* pair = s.selected >= 0 ? &s.pairs[s.selected] : nullptr;
  if (!pair || !pair->lidar_image) {
    if (s.loading_total) {
      ImGui::TextDisabled("loading %d / %d pairs ...", s.loading_done, s.loading_total);
    } else {
      ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
      ImGui::TextWrapped(
          "no dataset open: File > Open (Ctrl+O), or drop a dataset folder, a "
          "session or a recording (.bag .db3 .mcap) onto the window");
      ImGui::PopStyleColor();
    }
    return ImGui::End();
  }
  LidarToolbar(s, *pair, intents);
  const std::uint64_t key = LidarPictureKey(*pair, s.view.lidar_channel);
  if (key != lidar_key_) {
    gl_->lidar_picture.Upload(ComposeLidarPicture(*pair, s.view.lidar_channel), false);
    lidar_key_ = key;
  }
  CenterLidarOnBrush(*pair);
  LidarPicture(s, *pair, intents);
  ImGui::End();
}

// Channel, brush radius, clear; the plane fitted to the brush.
void Workbench::LidarToolbar(const Snapshot& s, const PairView& pair,
                             std::vector<Intent>* intents) {
  static const char* kChannels[] = {"intensity", "range", "ring"};
  int channel = static_cast<int>(s.view.lidar_channel);
  ImGui::SetNextItemWidth(110);
  if (ImGui::Combo("##channel", &channel, kChannels, 3)) {
    ViewState view = s.view;
    view.lidar_channel = static_cast<LidarChannel>(channel);
    intents->push_back(SetView{view});
  }
  SameLineIfFits(ToolbarItemWidth("brush [ ]", 110));
  ImGui::SetNextItemWidth(110);
  float radius = static_cast<float>(s.view.brush_radius_px);
  if (ImGui::SliderFloat("brush [ ]", &radius, 1.0f, 60.0f, "%.0f px",
                         ImGuiSliderFlags_AlwaysClamp)) {
    ViewState view = s.view;
    view.brush_radius_px = radius;
    intents->push_back(SetView{view});
  }
  SameLineIfFits(ToolbarItemWidth("clear"));
  if (ImGui::SmallButton("clear")) intents->push_back(ClearBrush{s.selected});
  // Second row: the board found again, the view back on it.
  if (ImGui::SmallButton("detect")) intents->push_back(DetectBoardAgain{s.selected, false});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("forget this pair's brush and find the board in the cloud again");
  SameLineIfFits(ToolbarItemWidth("detect all"));
  if (ImGui::SmallButton("detect all")) intents->push_back(DetectBoardAgain{s.selected, true});
  SameLineIfFits(ToolbarItemWidth("zoom to board"));
  if (ImGui::SmallButton("zoom to board")) {
    lidar_zoom_ = 0.0f;
    lidar_centered_on_.clear();
  }
  if (pair.lidar) {
    const BoardOrigin& origin = pair.board_origin;
    ImGui::Text("plane: %zu inliers of %d, RMS %.1f mm | board: %s", pair.lidar->inliers.size(),
                pair.lidar->num_candidates, pair.lidar->rms_m * 1e3,
                BoardSourceName(origin.source).c_str());
    if (origin.source == BoardSource::kDetected) {
      ImGui::SameLine();
      ImGui::TextColored({0.3f, 0.85f, 1.0f, 1}, "(confidence %.2f: %s)", origin.confidence,
                         origin.detail.c_str());
    }
  } else {
    ImGui::TextColored({1.0f, 0.5f, 0.4f, 1}, "no plane: %s", pair.lidar_failure.c_str());
  }
}

// A newly selected pair opens centred on its brush (the board), not on a fixed azimuth.
void Workbench::CenterLidarOnBrush(const PairView& pair) {
  if (lidar_centered_on_ == pair.id || pair.brush_pixels.empty()) return;
  // Circular mean: the brush may straddle the image's left/right seam.
  const int columns = pair.lidar_image->columns;
  double sx = 0, sy = 0, rows = 0;
  for (int pixel : pair.brush_pixels) {
    const double a = 2 * M_PI * ((pixel % columns) + 0.5) / columns;
    sx += std::cos(a), sy += std::sin(a);
    rows += pixel / columns + 0.5;
  }
  const double mean = std::atan2(sy, sx);
  lidar_center_ = static_cast<float>((mean < 0 ? mean + 2 * M_PI : mean) / (2 * M_PI));
  lidar_center_v_ = static_cast<float>(rows / pair.brush_pixels.size() / pair.lidar_image->rows);
  lidar_centered_on_ = pair.id;
}

// The picture zoomed horizontally about lidar_center_, its rows at the sensor's angular aspect
// (a VLP-16's 16 rings span 30 degrees: each row is drawn as tall as 2 degrees of azimuth are
// wide), cropped vertically about lidar_center_v_ when taller than the view. Over it: the brush
// outline (a circle in LiDAR pixels, an ellipse on screen); left drag paints (shift erases), the
// wheel zooms, a right drag pans.
void Workbench::LidarPicture(const Snapshot& s, const PairView& pair,
                             std::vector<Intent>* intents) {
  const LidarImage& image = *pair.lidar_image;
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const double vertical_rad = image.VerticalSpanRad();
  if (lidar_zoom_ <= 0) {  // fit: the rows fill the height
    lidar_zoom_ =
        vertical_rad > 0
            ? std::clamp(static_cast<float>(2 * M_PI * avail.y / (avail.x * vertical_rad)), 1.0f,
                         40.0f)
            : 3.0f;
    // A ring-less cloud (a swept or non-repetitive scanner) is rasterised over all it saw, its
    // rows as fine as its returns: the rows' fit can leave the board a sliver or crop it. The
    // board then fills 60 % of the width, its rows at most 80 % of the height.
    const auto [width_share, row_share] = BrushShares(pair);
    if (pair.cloud && pair.cloud->ring.empty() && width_share > 0) {
      double zoom = 0.6 / width_share;
      if (vertical_rad > 0)
        zoom = std::min(zoom, 0.8 * 2 * M_PI * avail.y / (avail.x * vertical_rad * row_share));
      lidar_zoom_ = std::clamp(static_cast<float>(zoom), 1.0f, 40.0f);
    }
  }
  const float span = 1.0f / std::max(1.0f, lidar_zoom_);
  lidar_center_ = std::clamp(lidar_center_, span / 2, 1 - span / 2);
  float height = avail.y, v0 = 0.0f, v1 = 1.0f;
  if (vertical_rad > 0) {
    const float full = static_cast<float>(vertical_rad * avail.x / (2 * M_PI * span));
    if (full <= avail.y) {
      height = full;
    } else {
      const float shown = avail.y / full;
      v0 = std::clamp(lidar_center_v_ - shown / 2, 0.0f, 1.0f - shown);
      v1 = v0 + shown;
    }
  }
  height = std::max(height, 1.0f);
  const ImVec2 uv0(lidar_center_ - span / 2, v0), uv1(lidar_center_ + span / 2, v1);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(TextureId(gl_->lidar_picture.texture()), ImVec2(avail.x, height), uv0, uv1);
  lidar_image_rect_ = {origin.x, origin.y, avail.x, height, uv0.x, uv1.x, v0, v1};
  if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) intents->push_back(EndStroke{});
  if (!ImGui::IsItemHovered()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const float col = (uv0.x + (io.MousePos.x - origin.x) / avail.x * span) * image.columns;
  const float row = (v0 + (io.MousePos.y - origin.y) / height * (v1 - v0)) * image.rows;
  const float rad = static_cast<float>(s.view.brush_radius_px);
  const float px_per_col = avail.x / (span * image.columns);
  const float px_per_row = height / ((v1 - v0) * image.rows);
  DrawEllipse(ImGui::GetWindowDrawList(), io.MousePos, rad * px_per_col, rad * px_per_row,
              io.KeyShift ? IM_COL32(255, 120, 90, 255) : IM_COL32(255, 255, 255, 220));
  if (ImGui::IsMouseDown(ImGuiMouseButton_Left))
    intents->push_back(
        BrushStroke{s.selected, static_cast<int>(row), static_cast<int>(col), rad, io.KeyShift});
  if (io.MouseWheel != 0)
    lidar_zoom_ = std::clamp(lidar_zoom_ * std::pow(1.25f, io.MouseWheel), 1.0f, 40.0f);
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Right)) {
    lidar_center_ -= io.MouseDelta.x / avail.x * span;
    lidar_center_v_ -= io.MouseDelta.y / height * (v1 - v0);
  }
}

}  // namespace calibench::ui
