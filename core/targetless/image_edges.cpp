#include "core/targetless/image_edges.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace calibench {
namespace {

cv::Mat GreyOf(const ImageU8& image) {
  cv::Mat wrapped(image.height, image.width, image.channels == 3 ? CV_8UC3 : CV_8UC1,
                  const_cast<std::uint8_t*>(image.data.data()));
  cv::Mat grey;
  if (image.channels == 3)
    cv::cvtColor(wrapped, grey, cv::COLOR_BGR2GRAY);
  else
    grey = wrapped.clone();
  return grey;
}

float Bilinear(const cv::Mat& m, double x, double y) {
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, m.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, m.rows - 2);
  const double wx = std::clamp(x - x0, 0.0, 1.0), wy = std::clamp(y - y0, 0.0, 1.0);
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y0 + 1);
  return static_cast<float>((1 - wy) * ((1 - wx) * r0[x0] + wx * r0[x0 + 1]) +
                            wy * ((1 - wx) * r1[x0] + wx * r1[x0 + 1]));
}

}  // namespace

bool ImageEdgeOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(blur_sigma_px >= 0)) return fail("the edge blur must be >= 0 pixels");
  if (!(high_quantile > 0 && high_quantile < 1)) return fail("the edge quantile must be in (0, 1)");
  if (!(low_ratio > 0 && low_ratio <= 1)) return fail("Canny's low ratio must be in (0, 1]");
  if (cell_px < 1) return fail("the edge grid's cell must be >= 1 pixel");
  return true;
}

ImageEdgeMap::ImageEdgeMap(int width, int height, int cell_px, std::vector<ImageEdge> edges)
    : width_(width), height_(height), cell_px_(cell_px) {
  cells_x_ = (width + cell_px - 1) / cell_px;
  cells_y_ = (height + cell_px - 1) / cell_px;
  auto cell_of = [&](const ImageEdge& e) {
    const int cx =
        std::clamp(static_cast<int>(std::floor((e.pixel.x() + 0.5) / cell_px_)), 0, cells_x_ - 1);
    const int cy =
        std::clamp(static_cast<int>(std::floor((e.pixel.y() + 0.5) / cell_px_)), 0, cells_y_ - 1);
    return cy * cells_x_ + cx;
  };
  cell_start_.assign(static_cast<size_t>(cells_x_) * cells_y_ + 1, 0);
  for (const ImageEdge& e : edges) ++cell_start_[cell_of(e) + 1];
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  edges_.resize(edges.size());
  std::vector<int> next(cell_start_.begin(), cell_start_.end() - 1);
  for (const ImageEdge& e : edges) edges_[next[cell_of(e)]++] = e;
  ComputeEmptyRings();
}

// Each cell's chessboard distance to the nearest cell with an edge (OpenCV's exact DIST_C
// transform over the cell grid), saturated at 255.
void ImageEdgeMap::ComputeEmptyRings() {
  empty_rings_.assign(static_cast<size_t>(cells_x_) * cells_y_, 255);
  if (edges_.empty()) return;
  cv::Mat empty(cells_y_, cells_x_, CV_8UC1);  // 0 where a cell holds an edge
  for (int c = 0; c < cells_x_ * cells_y_; ++c)
    empty.data[c] = cell_start_[c + 1] > cell_start_[c] ? 0 : 1;
  cv::Mat distance;
  cv::distanceTransform(empty, distance, cv::DIST_C, 3);
  cv::Mat rings(cells_y_, cells_x_, CV_8UC1, empty_rings_.data());
  distance.convertTo(rings, CV_8U);  // into empty_rings_, saturating
}

const ImageEdge* ImageEdgeMap::Nearest(const Vec2& pixel, double radius_px) const {
  if (edges_.empty()) return nullptr;
  const int cx = static_cast<int>(std::floor((pixel.x() + 0.5) / cell_px_));
  const int cy = static_cast<int>(std::floor((pixel.y() + 0.5) / cell_px_));
  const int max_ring = static_cast<int>(std::ceil(radius_px / cell_px_)) + 1;
  // Every edge in ring r (the cells r steps away, chessboard distance) lies at least
  // (r - 1) cells plus `margin` away: the query's distance to its own cell's nearest side.
  // A query outside the grid (none from the alignment) searches from ring 0 without a margin.
  int first_ring = 0;
  double margin = 0.0;
  if (cx >= 0 && cx < cells_x_ && cy >= 0 && cy < cells_y_) {
    const double fx = pixel.x() + 0.5 - cx * cell_px_, fy = pixel.y() + 0.5 - cy * cell_px_;
    margin = std::min({fx, cell_px_ - fx, fy, cell_px_ - fy});
    first_ring = empty_rings_[cy * cells_x_ + cx];  // the rings before it hold no edge
    if ((first_ring - 1) * cell_px_ + margin >= radius_px) return nullptr;
  }
  const ImageEdge* best = nullptr;
  double best_d2 = radius_px * radius_px;
  for (int ring = first_ring; ring <= max_ring; ++ring) {
    if (best && (ring - 1) * cell_px_ + margin > std::sqrt(best_d2)) break;
    for (int y = cy - ring; y <= cy + ring; ++y) {
      if (y < 0 || y >= cells_y_) continue;
      const bool edge_row = y == cy - ring || y == cy + ring;
      for (int x = cx - ring; x <= cx + ring; x += (edge_row ? 1 : 2 * std::max(ring, 1))) {
        if (x < 0 || x >= cells_x_) continue;
        const int c = y * cells_x_ + x;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
          const double d2 = (edges_[k].pixel - pixel).squaredNorm();
          if (d2 < best_d2) best_d2 = d2, best = &edges_[k];
        }
      }
    }
  }
  return best;
}

ImageEdgeMap DetectImageEdges(const ImageU8& image, const ImageEdgeOptions& options) {
  if (image.empty()) return ImageEdgeMap(image.width, image.height, options.cell_px, {});
  cv::Mat grey = GreyOf(image);
  if (options.blur_sigma_px > 0) cv::GaussianBlur(grey, grey, cv::Size(), options.blur_sigma_px);
  cv::Mat dx, dy;
  cv::Sobel(grey, dx, CV_16S, 1, 0, 3);
  cv::Sobel(grey, dy, CV_16S, 0, 1, 3);
  cv::Mat magnitude;
  cv::Mat dxf, dyf;
  dx.convertTo(dxf, CV_32F);
  dy.convertTo(dyf, CV_32F);
  cv::magnitude(dxf, dyf, magnitude);
  // Canny's thresholds from the gradient's own distribution (L2 gradient, as `magnitude`).
  std::vector<float> sample;
  sample.reserve(magnitude.total() / 7 + 1);
  for (size_t i = 0; i < magnitude.total(); i += 7) sample.push_back(magnitude.ptr<float>()[i]);
  const size_t k = static_cast<size_t>(options.high_quantile * (sample.size() - 1));
  std::nth_element(sample.begin(), sample.begin() + k, sample.end());
  const double high = std::max(1.0, static_cast<double>(sample[k]));
  cv::Mat edge_mask;
  cv::Canny(dx, dy, edge_mask, options.low_ratio * high, high, true);

  std::vector<ImageEdge> edges;
  for (int y = 1; y + 1 < edge_mask.rows; ++y) {
    const std::uint8_t* row = edge_mask.ptr<std::uint8_t>(y);
    for (int x = 1; x + 1 < edge_mask.cols; ++x) {
      if (!row[x]) continue;
      const Vec2 g(dxf.at<float>(y, x), dyf.at<float>(y, x));
      const double g_norm = g.norm();
      if (!(g_norm > 0)) continue;
      const Vec2 n = g / g_norm;
      // The gradient's peak across the edge, by a parabola through three samples along n.
      const double m0 = magnitude.at<float>(y, x);
      const double mm = Bilinear(magnitude, x - n.x(), y - n.y());
      const double mp = Bilinear(magnitude, x + n.x(), y + n.y());
      const double curvature = mm - 2 * m0 + mp;
      double offset = curvature < 0 ? 0.5 * (mm - mp) / curvature : 0.0;
      offset = std::clamp(offset, -0.5, 0.5);
      edges.push_back({Vec2(x, y) + offset * n, n});
    }
  }
  return ImageEdgeMap(image.width, image.height, options.cell_px, std::move(edges));
}

}  // namespace calibench
