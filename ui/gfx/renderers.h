// Small retained-mode renderers over GL 3.3 core: points, lines, translucent triangles and
// textured images. They know nothing of ImGui or of calibration data: callers pass float arrays
// and a 4x4 view-projection matrix (column-major, OpenGL clip space).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/base/image.h"

namespace calibench::gfx {

using Matrix4f = Eigen::Matrix4f;
struct Rgba {
  std::uint8_t r = 255, g = 255, b = 255, a = 255;
};

// Round, depth-tested points with per-point colour; size in pixels.
class PointRenderer {
 public:
  PointRenderer();
  ~PointRenderer();
  void Upload(const std::vector<Eigen::Vector3f>& positions, const std::vector<Rgba>& colors);
  void Draw(const Matrix4f& view_projection, float point_size_px, float opacity = 1.0f) const;
  size_t size() const { return count_; }

 private:
  std::uint32_t program_ = 0, vao_ = 0, vbo_positions_ = 0, vbo_colors_ = 0;
  size_t count_ = 0;
};

// Line segments (pairs of vertices) with per-vertex colour.
class LineRenderer {
 public:
  LineRenderer();
  ~LineRenderer();
  void Upload(const std::vector<Eigen::Vector3f>& vertices, const std::vector<Rgba>& colors);
  void Draw(const Matrix4f& view_projection, float width_px = 1.0f) const;

 private:
  std::uint32_t program_ = 0, vao_ = 0, vbo_positions_ = 0, vbo_colors_ = 0;
  size_t count_ = 0;
};

// Triangles (triples of vertices) with per-vertex colour and alpha blending; for board quads.
class TriangleRenderer {
 public:
  TriangleRenderer();
  ~TriangleRenderer();
  void Upload(const std::vector<Eigen::Vector3f>& vertices, const std::vector<Rgba>& colors);
  void Draw(const Matrix4f& view_projection) const;

 private:
  std::uint32_t program_ = 0, vao_ = 0, vbo_positions_ = 0, vbo_colors_ = 0;
  size_t count_ = 0;
};

// A texture from an ImageU8 (grey or BGR), drawn as a screen-aligned rectangle given in
// normalized device coordinates. Nearest or linear filtering.
class ImageTexture {
 public:
  ImageTexture() = default;
  ~ImageTexture();
  void Upload(const ImageU8& image, bool linear_filtering = true);
  // Draws the texture into [x0, x1] x [y0, y1] (NDC, y up) of the bound target.
  void Draw(float x0, float y0, float x1, float y1) const;
  std::uint32_t texture() const { return texture_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  std::uint32_t texture_ = 0;
  mutable std::uint32_t program_ = 0, vao_ = 0, vbo_ = 0;
  int width_ = 0, height_ = 0;
};

// Perspective and look-at helpers (right-handed, OpenGL conventions).
Matrix4f Perspective(float fovy_rad, float aspect, float near_m, float far_m);
Matrix4f LookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                const Eigen::Vector3f& up);

}  // namespace calibench::gfx
