// Round points drawn in software, with the rasterisation rules of GL_POINTS and points.frag.glsl,
// for OpenGL implementations that are software themselves.
//
// Why: llvmpipe (Mesa's CPU rasteriser: virtual machines, remote desktops, laptops without a GPU
// driver, our CI) spends about 170 ns per visible GL point in setup and binning on the calling
// thread, and as much again rasterising. The 3D view turned over a 131k-point cloud cost 14 ms of
// a 16 ms frame that way. This loop does the same work in about 70 ns per visible point and next
// to nothing per point outside the view; PointRenderer uploads its result as two textures and
// writes them into the target with depth (see PointRenderer::Draw).
#pragma once

#include <cstdint>
#include <vector>

#include "ui/gfx/renderers.h"

namespace calibench::gfx {

// A viewport's worth of splatted points, rows bottom-up (GL window coordinates).
struct PointSplat {
  // depth of a pixel no point covers; above every 24-bit depth
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  int width = 0, height = 0;
  std::vector<Rgba> color;  // meaningful where depth is not kEmpty (not cleared between splats)
  // Window depth as the 24-bit integer a GL_DEPTH_COMPONENT24 buffer stores, kEmpty if none.
  std::vector<std::uint32_t> depth;
};

// The point sizes SplatPoints draws, in pixels: llvmpipe's GL_POINT_SIZE_RANGE.
inline constexpr float kMinPointSizePx = 1.0f, kMaxPointSizePx = 255.0f;

// Draws positions[i] in colors[i] through view_projection into a width x height viewport, as
// GL_POINTS of point_size_px pixels (clamped to the range above) with points.frag.glsl's disc
// would on llvmpipe:
// - a point whose position lies outside the clip volume is dropped (GL's rule for points);
// - it covers the pixels whose centres lie inside its square (half-open: left and bottom edges
//   in, right and top out) and inside its inscribed disc (its rim included);
// - depth is tested as GL_LEQUAL in the order of the points, so a later point at the same 24-bit
//   depth wins.
// Opaque points only: the caller keeps translucent ones on GL. Reuses out's buffers.
void SplatPoints(const std::vector<Eigen::Vector3f>& positions, const std::vector<Rgba>& colors,
                 const Matrix4f& view_projection, float point_size_px, int width, int height,
                 PointSplat* out);

}  // namespace calibench::gfx
