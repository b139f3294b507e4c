// Small retained-mode renderers over GL 3.3 core: points, lines, translucent triangles and
// textured images. They know nothing of ImGui or of calibration data: callers pass float arrays
// and a 4x4 view-projection matrix (column-major, OpenGL clip space).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/base/image.h"

namespace calibench::gfx {

using Matrix4f = Eigen::Matrix4f;
struct Rgba {
  std::uint8_t r = 255, g = 255, b = 255, a = 255;
};

// What points, lines and triangles share: a program and a vertex array of positions with one
// RGBA colour each, uploaded whole. Not copyable (it owns GL names).
class ColoredVertices {
 public:
  ColoredVertices(const ColoredVertices&) = delete;
  ColoredVertices& operator=(const ColoredVertices&) = delete;
  // Equal counts, a multiple of the primitive's vertex count (1, 2 or 3); std::invalid_argument
  // otherwise. Virtual: PointRenderer keeps a CPU copy for its software splat.
  virtual void Upload(const std::vector<Eigen::Vector3f>& positions,
                      const std::vector<Rgba>& colors);
  size_t size() const { return count_; }

 protected:
  // name: for messages; group: vertices per primitive. Requires a current context.
  ColoredVertices(const char* name, const char* vertex_shader, const char* fragment_shader,
                  size_t group);
  virtual ~ColoredVertices();
  // Sets the program, its view_projection and all the state a draw depends on; false when there
  // is nothing to draw. depth_write: whether the primitives hide what is drawn after them (off
  // lets translucent surfaces show what lies behind them whatever the draw order).
  bool Prepare(const Matrix4f& view_projection, bool depth_write) const;
  // Draws every vertex as `mode` primitives (GL_POINTS, ...) and restores the state.
  void DrawAll(std::uint32_t mode) const;
  std::uint32_t program() const { return program_; }

 private:
  const char* name_;
  size_t group_;
  std::uint32_t program_ = 0, vao_ = 0, vbo_positions_ = 0, vbo_colors_ = 0;
  size_t count_ = 0;
};

struct PointSplat;

// How a PointRenderer rasterises opaque points. On llvmpipe the two pictures agree in all but a
// few pixels in 100,000 (depth ties; GfxPointSplat compares them) and kSoftwareSplat is three to
// four times faster; GL_POINTS is what any GPU draws fastest.
enum class PointDrawing { kGlPoints, kSoftwareSplat };

// Whether the current context rasterises on the CPU (Mesa's llvmpipe or softpipe, SwiftShader).
bool IsSoftwareRenderer();

// The drawing PointRenderers constructed from now on use: `drawing`, or with nullopt (the
// default) the software splat on a software renderer and GL_POINTS elsewhere. Process-wide; for
// benchmarks and tests that compare the two.
void SetPointDrawingForNewRenderers(std::optional<PointDrawing> drawing);

// Round, depth-tested points with per-point colour; size in pixels.
class PointRenderer : public ColoredVertices {
 public:
  // See SetPointDrawingForNewRenderers for the drawing it starts with.
  PointRenderer();
  ~PointRenderer() override;
  void Upload(const std::vector<Eigen::Vector3f>& positions,
              const std::vector<Rgba>& colors) override;
  void Draw(const Matrix4f& view_projection, float point_size_px, float opacity = 1.0f) const;
  // Translucent points (opacity < 1 or a colour's alpha < 255) always go to GL_POINTS: their
  // blending depends on the draw order of everything, which only GL sees. The points of a splat
  // are kept on the CPU side at Upload, so choose the drawing before it (std::logic_error after).
  void set_drawing(PointDrawing drawing);
  PointDrawing drawing() const { return drawing_; }

 private:
  void DrawSplat(const Matrix4f& view_projection, float point_size_px) const;

  PointDrawing drawing_;
  // For kSoftwareSplat only: the points on the CPU side too, and the splat's buffers and
  // textures.
  std::vector<Eigen::Vector3f> positions_;
  std::vector<Rgba> colors_;
  bool all_opaque_ = true;
  mutable std::unique_ptr<PointSplat> splat_;
  mutable std::uint32_t splat_program_ = 0, splat_vao_ = 0, splat_color_ = 0, splat_depth_ = 0;
  mutable int splat_width_ = 0, splat_height_ = 0;
};

// Line segments (pairs of vertices) with per-vertex colour.
class LineRenderer : public ColoredVertices {
 public:
  LineRenderer();
  void Draw(const Matrix4f& view_projection, float width_px = 1.0f) const;
};

// Triangles (triples of vertices) with per-vertex colour and alpha blending; for board quads.
class TriangleRenderer : public ColoredVertices {
 public:
  TriangleRenderer();
  void Draw(const Matrix4f& view_projection) const;
};

// Line segments gathered for a LineRenderer: two vertices and two colours per segment.
struct LineBatch {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Rgba> colors;
  void Add(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Rgba color);
  // The frame's x, y and z axes (red, green, blue), `length` long from its origin.
  void AddAxes(const Eigen::Isometry3d& world_from_frame, double length);
};

// Triangles gathered for a TriangleRenderer: three vertices and three colours per triangle.
struct TriangleBatch {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Rgba> colors;
  // The quadrilateral c0 c1 c2 c3 as the triangles (c0, c1, c2) and (c0, c2, c3).
  void AddQuad(const std::array<Eigen::Vector3d, 4>& corners, Rgba color);
  // A width x height rectangle centred on the frame's origin, in its xy plane.
  void AddRectangle(const Eigen::Isometry3d& world_from_frame, double width, double height,
                    Rgba color);
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
