// Edges of a camera image for point-to-edge alignment (docs/targetless.md "Image edges"): Canny's
// edge pixels, each moved to the sub-pixel peak of the gradient across it, with its normal, and a
// grid that answers "the nearest edge to this pixel within r".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"

namespace calibench {

struct ImageEdgeOptions {
  double blur_sigma_px = 1.2;  // Gaussian smoothing before the gradient (pixels)
  // Canny's thresholds from the image's own gradients: the high one at this quantile of the
  // gradient magnitude, the low one this fraction of it.
  double high_quantile = 0.90;
  double low_ratio = 0.4;
  int cell_px = 4;  // the lookup grid's cell (pixels)

  bool Check(std::string* why) const;
};

struct ImageEdge {
  Vec2 pixel = Vec2::Zero();    // sub-pixel, OpenCV pixel convention
  Vec2 normal = Vec2::UnitX();  // unit, across the edge (the gradient's direction)
};

class ImageEdgeMap {
 public:
  ImageEdgeMap() = default;
  ImageEdgeMap(int width, int height, int cell_px, std::vector<ImageEdge> edges);

  // The edge nearest to `pixel` within `radius_px`; nullptr when there is none.
  const ImageEdge* Nearest(const Vec2& pixel, double radius_px) const;

  const std::vector<ImageEdge>& edges() const { return edges_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void ComputeEmptyRings();

  int width_ = 0, height_ = 0, cell_px_ = 8, cells_x_ = 0, cells_y_ = 0;
  std::vector<ImageEdge> edges_;  // ordered by cell
  std::vector<int> cell_start_;   // edges_[cell_start_[c] .. cell_start_[c + 1])
  // Per cell, the Chebyshev distance in cells to the nearest cell holding an edge (capped at 255):
  // the rings Nearest may skip, and every edge is at least (distance - 1) cells away, so a search
  // whose radius is shorter ends before looking at any cell. Most of the alignment's queries at
  // its final radius find nothing; this answers them without a search.
  std::vector<std::uint8_t> empty_rings_;
};

ImageEdgeMap DetectImageEdges(const ImageU8& image, const ImageEdgeOptions& options);

}  // namespace calibench
