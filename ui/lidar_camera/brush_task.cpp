// The brush intents: dabs merged into the pair's brush, the record first, then a refit.
#include "ui/lidar_camera/brush_task.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace calibench::ui {
namespace {

// Pixels of a circle on the LiDAR image; columns wrap around (azimuth is periodic).
std::vector<int> CirclePixels(int rows, int columns, int row, int column, float radius) {
  std::vector<int> pixels;
  const int r = static_cast<int>(std::ceil(radius));
  for (int dr = -r; dr <= r; ++dr) {
    const int y = row + dr;
    if (y < 0 || y >= rows) continue;
    for (int dc = -r; dc <= r; ++dc) {
      if (dr * dr + dc * dc > radius * radius) continue;
      const int x = ((column + dc) % columns + columns) % columns;
      pixels.push_back(y * columns + x);
    }
  }
  std::sort(pixels.begin(), pixels.end());
  return pixels;
}

}  // namespace

const LidarImage* BrushTask::ImageOf(int index) const {
  host_.mutex.AssertHeld(__func__);
  if (index < 0 || index >= static_cast<int>(host_.state.pairs.size())) return nullptr;
  return host_.state.pairs[index].lidar_image.get();
}

void BrushTask::Paint(const BrushStroke& stroke) {
  const LidarImage* image = ImageOf(stroke.index);
  if (!image) return;
  Merge(stroke.index,
        CirclePixels(image->rows, image->columns, stroke.row, stroke.column, stroke.radius_px),
        stroke.erase);
}

void BrushTask::Paint(const PaintPoints& points) {
  if (ImageOf(points.index)) Merge(points.index, points.pixels, points.erase);
}

void BrushTask::Clear(const ClearBrush& clear) {
  if (!ImageOf(clear.index)) return;
  SetBrush(clear.index, {}, /*amend=*/false);
  controls_.refit(clear.index);
}

void BrushTask::DetectAgain(const DetectBoardAgain& again) {
  if (!again.all && !ImageOf(again.index)) return;
  const SharedPairs<PairView>& pairs = host_.state.pairs;
  bool first = true;  // every pair's brush forgotten in one undo step
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!again.all && static_cast<int>(i) != again.index) continue;
    if (!pairs[i].lidar_image) continue;
    controls_.job()->SetBrush(pairs[i].id, std::nullopt, /*amend=*/!first);
    first = false;
    controls_.refit(static_cast<int>(i));
  }
  if (!first) controls_.edited();
}

void BrushTask::SetBrush(int index, std::vector<int> pixels, bool amend) {
  const PairView& pair = host_.state.pairs.at(index);
  PairEdit brush;
  brush.brush_pixels = std::move(pixels);
  brush.brush_rows = pair.lidar_image->rows;
  brush.brush_columns = pair.lidar_image->columns;
  controls_.job()->SetBrush(pair.id, brush, amend);
  controls_.edited();
}

void BrushTask::Merge(int index, const std::vector<int>& pixels, bool erase) {
  const std::vector<int>& brush = host_.state.pairs.at(index).brush_pixels;
  std::vector<int> merged;
  if (erase)
    std::set_difference(brush.begin(), brush.end(), pixels.begin(), pixels.end(),
                        std::back_inserter(merged));
  else
    std::set_union(brush.begin(), brush.end(), pixels.begin(), pixels.end(),
                   std::back_inserter(merged));
  if (merged == brush) return;
  // Painted: the brush replaces the seed and any detection from now on.
  SetBrush(index, std::move(merged), /*amend=*/stroke_open_);
  stroke_open_ = true;  // the stroke's later dabs amend this undo step
  controls_.refit(index);
}

}  // namespace calibench::ui
