#include "ui/gfx/point_splat.h"

#include <algorithm>
#include <cmath>

#include "core/base/types.h"

namespace calibench::gfx {

void SplatPoints(const std::vector<Eigen::Vector3f>& positions, const std::vector<Rgba>& colors,
                 const Matrix4f& view_projection, float point_size_px, int width, int height,
                 PointSplat* out) {
  CALIBENCH_CHECK(positions.size() == colors.size() && width > 0 && height > 0);
  // GL clamps a point size to the implementation's range; llvmpipe's is [1, 255] px. A size that
  // is not a number (a hand-edited session) draws the smallest point.
  point_size_px = std::isnan(point_size_px)
                      ? kMinPointSizePx
                      : std::clamp(point_size_px, kMinPointSizePx, kMaxPointSizePx);
  const size_t pixels = static_cast<size_t>(width) * height;
  out->width = width;
  out->height = height;
  out->color.resize(pixels);
  out->depth.assign(pixels, PointSplat::kEmpty);
  const float half_size = 0.5f * point_size_px;
  // points.frag.glsl keeps |gl_PointCoord - 0.5|^2 <= 0.25, gl_PointCoord = 0.5 + offset / size:
  // the pixel centre's offset from the point, squared, at most (size / 2)^2.
  const float radius_squared = half_size * half_size;
  const Eigen::Matrix<float, 4, 4> m = view_projection;
  const float half_width = 0.5f * static_cast<float>(width);
  const float half_height = 0.5f * static_cast<float>(height);
  for (size_t i = 0; i < positions.size(); ++i) {
    const Eigen::Vector4f clip = m * positions[i].homogeneous();
    const float w = clip.w();
    // Inside the clip volume: -w <= x, y, z <= w (so w >= 0). A finite w keeps an infinite
    // coordinate out (inf <= inf would let it in); NaN fails every comparison.
    if (!(std::isfinite(w) && w > 0.0f && std::abs(clip.x()) <= w && std::abs(clip.y()) <= w &&
          std::abs(clip.z()) <= w))
      continue;
    const float inverse_w = 1.0f / w;
    // Viewport transform with glDepthRange(0, 1): window x, y in pixels from the bottom left.
    // Written as scale and offset, the way GL implementations apply it, for the same rounding.
    const float window_x = clip.x() * inverse_w * half_width + half_width;
    const float window_y = clip.y() * inverse_w * half_height + half_height;
    const float window_z = clip.z() * inverse_w * 0.5f + 0.5f;
    // A w so small that 1 / w overflows (|x| <= w then holds for x = 0 only) gives inf or NaN.
    if (!(std::isfinite(window_x) && std::isfinite(window_y) && std::isfinite(window_z))) continue;
    // To 24 bits by truncation: on the demo's 3D view this agrees with llvmpipe's GL_POINTS in
    // all but 14 of 120,000 pixels, rounding in 60 (depth ties among far points).
    const auto depth = static_cast<std::uint32_t>(window_z * 16777215.0f);
    // Pixels whose centre (x + 0.5, y + 0.5) lies in the point's square, half-open like
    // llvmpipe's: a centre on the left or bottom edge is in, on the right or top edge out.
    const int x0 = std::max(0, static_cast<int>(std::ceil(window_x - half_size - 0.5f)));
    const int x1 =
        std::min(width - 1, static_cast<int>(std::ceil(window_x + half_size - 0.5f)) - 1);
    const int y0 = std::max(0, static_cast<int>(std::ceil(window_y - half_size - 0.5f)));
    const int y1 =
        std::min(height - 1, static_cast<int>(std::ceil(window_y + half_size - 0.5f)) - 1);
    for (int y = y0; y <= y1; ++y) {
      const float dy = static_cast<float>(y) + 0.5f - window_y;
      const size_t row = static_cast<size_t>(y) * width;
      for (int x = x0; x <= x1; ++x) {
        const float dx = static_cast<float>(x) + 0.5f - window_x;
        if (dx * dx + dy * dy > radius_squared) continue;
        std::uint32_t& stored = out->depth[row + x];
        if (depth <= stored) {
          stored = depth;
          out->color[row + x] = colors[i];
        }
      }
    }
  }
}

}  // namespace calibench::gfx
