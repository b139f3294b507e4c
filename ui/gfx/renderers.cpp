#include "ui/gfx/renderers.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/base/types.h"
#include "ui/gfx/gl_api.h"
#include "ui/gfx/point_splat.h"
#include "ui/gfx/shader.h"
#include "ui/gfx/shader_sources.h"

namespace calibench::gfx {

// Positions go to GL straight from the std::vector, so the element layouts must be packed.
static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
static_assert(sizeof(Rgba) == 4);

ColoredVertices::ColoredVertices(const char* name, const char* vertex_shader,
                                 const char* fragment_shader, size_t group)
    : name_(name), group_(group) {
  program_ = BuildProgram(name, vertex_shader, fragment_shader);
  // Location 0 = vec3 position, location 1 = RGBA8 colour normalized to [0, 1].
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &vbo_positions_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_positions_);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Eigen::Vector3f), nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, &vbo_colors_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_colors_);
  glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Rgba), nullptr);
  glEnableVertexAttribArray(1);
  glBindVertexArray(0);
}

ColoredVertices::~ColoredVertices() {
  if (program_) glDeleteProgram(program_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_positions_) glDeleteBuffers(1, &vbo_positions_);
  if (vbo_colors_) glDeleteBuffers(1, &vbo_colors_);
}

void ColoredVertices::Upload(const std::vector<Eigen::Vector3f>& positions,
                             const std::vector<Rgba>& colors) {
  if (positions.size() != colors.size() || positions.size() % group_ != 0) {
    throw std::invalid_argument(std::string(name_) + ": " + std::to_string(positions.size()) +
                                " vertices and " + std::to_string(colors.size()) +
                                " colours; need equal counts, a multiple of " +
                                std::to_string(group_));
  }
  glBindBuffer(GL_ARRAY_BUFFER, vbo_positions_);
  glBufferData(GL_ARRAY_BUFFER, positions.size() * sizeof(Eigen::Vector3f), positions.data(),
               GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_colors_);
  glBufferData(GL_ARRAY_BUFFER, colors.size() * sizeof(Rgba), colors.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  count_ = positions.size();
}

bool ColoredVertices::Prepare(const Matrix4f& view_projection, bool depth_write) const {
  if (count_ == 0) return false;
  // ImGui and other views leave their state behind: set all of it.
  glUseProgram(program_);
  glUniformMatrix4fv(glGetUniformLocation(program_, "view_projection"), 1, GL_FALSE,
                     view_projection.data());
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);  // lines drawn over a quad at the same depth stay visible
  glDepthMask(depth_write ? GL_TRUE : GL_FALSE);
  glDisable(GL_CULL_FACE);
  // "Over" for colour; alpha accumulates towards 1 so that the framebuffer stays opaque when
  // its texture is later blended into an ImGui window.
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  return true;
}

void ColoredVertices::DrawAll(std::uint32_t mode) const {
  glBindVertexArray(vao_);
  glDrawArrays(mode, 0, static_cast<GLsizei>(count_));
  glBindVertexArray(0);
  glUseProgram(0);
  glDepthMask(GL_TRUE);
}

bool IsSoftwareRenderer() {
  const GLubyte* text = glGetString(GL_RENDERER);
  if (!text) return false;
  const std::string renderer(reinterpret_cast<const char*>(text));
  for (const char* software : {"llvmpipe", "softpipe", "SwiftShader", "Software Rasterizer"})
    if (renderer.find(software) != std::string::npos) return true;
  return false;
}

namespace {
std::atomic<int> point_drawing_for_new_renderers{-1};  // -1: by renderer, else a PointDrawing
}  // namespace

void SetPointDrawingForNewRenderers(std::optional<PointDrawing> drawing) {
  point_drawing_for_new_renderers = drawing ? static_cast<int>(*drawing) : -1;
}

PointRenderer::PointRenderer()
    : ColoredVertices("points", shader_sources::kPointsVert, shader_sources::kPointsFrag, 1) {
  const int drawing = point_drawing_for_new_renderers;
  drawing_ = drawing >= 0           ? static_cast<PointDrawing>(drawing)
             : IsSoftwareRenderer() ? PointDrawing::kSoftwareSplat
                                    : PointDrawing::kGlPoints;
}

PointRenderer::~PointRenderer() {
  if (splat_program_) glDeleteProgram(splat_program_);
  if (splat_vao_) glDeleteVertexArrays(1, &splat_vao_);
  if (splat_color_) glDeleteTextures(1, &splat_color_);
  if (splat_depth_) glDeleteTextures(1, &splat_depth_);
}

void PointRenderer::set_drawing(PointDrawing drawing) {
  if (drawing == drawing_) return;
  if (size() > 0) throw std::logic_error("PointRenderer::set_drawing after Upload");
  drawing_ = drawing;
}

void PointRenderer::Upload(const std::vector<Eigen::Vector3f>& positions,
                           const std::vector<Rgba>& colors) {
  ColoredVertices::Upload(positions, colors);
  if (drawing_ != PointDrawing::kSoftwareSplat) return;  // GPUs: no copy
  positions_ = positions;
  colors_ = colors;
  all_opaque_ = std::all_of(colors.begin(), colors.end(), [](Rgba c) { return c.a == 255; });
}

void PointRenderer::Draw(const Matrix4f& view_projection, float point_size_px,
                         float opacity) const {
  if (drawing_ == PointDrawing::kSoftwareSplat && opacity >= 1.0f && all_opaque_) {
    if (size() > 0) DrawSplat(view_projection, point_size_px);
    return;
  }
  // Translucent points must not hide each other, opaque ones must.
  if (!Prepare(view_projection, opacity >= 1.0f)) return;
  glUniform1f(glGetUniformLocation(program(), "point_size_px"), point_size_px);
  glUniform1f(glGetUniformLocation(program(), "opacity"), std::clamp(opacity, 0.0f, 1.0f));
  glEnable(GL_PROGRAM_POINT_SIZE);  // size from gl_PointSize in the vertex shader
  DrawAll(GL_POINTS);
}

void PointRenderer::DrawSplat(const Matrix4f& view_projection, float point_size_px) const {
  GLint viewport[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, viewport);
  const int width = viewport[2], height = viewport[3];
  if (width <= 0 || height <= 0) return;
  if (!splat_) splat_ = std::make_unique<PointSplat>();
  SplatPoints(positions_, colors_, view_projection, point_size_px, width, height, splat_.get());
  if (!splat_program_) {
    splat_program_ = BuildProgram("splat", shader_sources::kSplatVert, shader_sources::kSplatFrag);
    glGenVertexArrays(1, &splat_vao_);  // core profile draws need one, even without attributes
    glGenTextures(1, &splat_color_);
    glGenTextures(1, &splat_depth_);
  }
  // The state this draw changes and gives back: texture unit and its bindings, unpacking, blend.
  GLint previous_active = 0, previous_alignment = 0, previous_row_length = 0;
  GLint previous_textures[2] = {0, 0};
  glGetIntegerv(GL_ACTIVE_TEXTURE, &previous_active);
  for (int unit = 0; unit < 2; ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &previous_textures[unit]);
  }
  const bool previous_blend = glIsEnabled(GL_BLEND) == GL_TRUE;
  glGetIntegerv(GL_UNPACK_ALIGNMENT, &previous_alignment);
  glGetIntegerv(GL_UNPACK_ROW_LENGTH, &previous_row_length);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // 4-byte texels: rows are always aligned
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  const bool reallocate = width != splat_width_ || height != splat_height_;
  const struct {
    GLuint texture;
    GLint internal_format;
    GLenum format, type;
    const void* data;
  } layers[2] = {{splat_color_, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, splat_->color.data()},
                 {splat_depth_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, splat_->depth.data()}};
  for (int unit = 0; unit < 2; ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, layers[unit].texture);
    if (reallocate) {
      glTexImage2D(GL_TEXTURE_2D, 0, layers[unit].internal_format, width, height, 0,
                   layers[unit].format, layers[unit].type, layers[unit].data);
      // texelFetch ignores filtering, but an integer texture with a mipmapping default filter
      // is incomplete and reads as zero.
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    } else {
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, layers[unit].format, layers[unit].type,
                      layers[unit].data);
    }
  }
  splat_width_ = width;
  splat_height_ = height;
  glPixelStorei(GL_UNPACK_ALIGNMENT, previous_alignment);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, previous_row_length);
  glUseProgram(splat_program_);
  glUniform1i(glGetUniformLocation(splat_program_, "splat_color"), 0);
  glUniform1i(glGetUniformLocation(splat_program_, "splat_depth"), 1);
  glUniform2i(glGetUniformLocation(splat_program_, "viewport_origin"), viewport[0], viewport[1]);
  // Opaque points hide what lies behind them and replace the colour (GL_POINTS' blending with
  // alpha 1 does the same); the depth test decides against what is already drawn.
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(splat_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glUseProgram(0);
  for (int unit = 0; unit < 2; ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(previous_textures[unit]));
  }
  glActiveTexture(static_cast<GLenum>(previous_active));
  if (previous_blend) glEnable(GL_BLEND);
}

LineRenderer::LineRenderer()
    : ColoredVertices("lines", shader_sources::kColoredVert, shader_sources::kColoredFrag, 2) {}

void LineRenderer::Draw(const Matrix4f& view_projection, float width_px) const {
  if (!Prepare(view_projection, true)) return;
  // Wide lines are deprecated in core profile: a forward-compatible context (macOS) rejects
  // widths above 1 and drivers clamp to GL_ALIASED_LINE_WIDTH_RANGE (Mesa: up to 255, NVIDIA:
  // about 10). So width_px is a wish that may be ignored; views must not rely on it.
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  GLfloat range[2] = {1.0f, 1.0f};
  glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, range);
  const bool forward_compatible = (flags & GL_CONTEXT_FLAG_FORWARD_COMPATIBLE_BIT) != 0;
  glLineWidth(forward_compatible ? 1.0f : std::clamp(width_px, range[0], range[1]));
  DrawAll(GL_LINES);
  glLineWidth(1.0f);
}

TriangleRenderer::TriangleRenderer()
    : ColoredVertices("triangles", shader_sources::kColoredVert, shader_sources::kColoredFrag, 3) {}

void TriangleRenderer::Draw(const Matrix4f& view_projection) const {
  // Depth test on (points behind a board quad are tinted by it), depth write off (the quad hides
  // nothing drawn after it, and two quads blend whatever their order).
  if (!Prepare(view_projection, false)) return;
  DrawAll(GL_TRIANGLES);
}

void LineBatch::Add(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Rgba color) {
  vertices.push_back(a.cast<float>());
  vertices.push_back(b.cast<float>());
  colors.push_back(color);
  colors.push_back(color);
}

void LineBatch::AddAxes(const Eigen::Isometry3d& world_from_frame, double length) {
  const Rgba axis_colors[3] = {{255, 60, 60, 255}, {60, 230, 60, 255}, {80, 120, 255, 255}};
  for (int a = 0; a < 3; ++a)
    Add(world_from_frame.translation(), world_from_frame * (Eigen::Vector3d::Unit(a) * length),
        axis_colors[a]);
}

void TriangleBatch::AddQuad(const std::array<Eigen::Vector3d, 4>& corners, Rgba color) {
  for (int k : {0, 1, 2, 0, 2, 3}) {
    vertices.push_back(corners[k].cast<float>());
    colors.push_back(color);
  }
}

void TriangleBatch::AddRectangle(const Eigen::Isometry3d& world_from_frame, double width,
                                 double height, Rgba color) {
  const double hw = width / 2, hh = height / 2;
  AddQuad({world_from_frame * Eigen::Vector3d(-hw, -hh, 0),
           world_from_frame * Eigen::Vector3d(hw, -hh, 0),
           world_from_frame * Eigen::Vector3d(hw, hh, 0),
           world_from_frame * Eigen::Vector3d(-hw, hh, 0)},
          color);
}

Matrix4f Perspective(float fovy_rad, float aspect, float near_m, float far_m) {
  CALIBENCH_CHECK(fovy_rad > 0.0f && fovy_rad < std::numbers::pi_v<float>);
  CALIBENCH_CHECK(aspect > 0.0f && near_m > 0.0f && far_m > near_m);
  // gluPerspective: eye-space z in [-near, -far] maps to NDC z in [-1, 1].
  const float focal = 1.0f / std::tan(0.5f * fovy_rad);
  Matrix4f m = Matrix4f::Zero();
  m(0, 0) = focal / aspect;
  m(1, 1) = focal;
  m(2, 2) = (far_m + near_m) / (near_m - far_m);
  m(2, 3) = 2.0f * far_m * near_m / (near_m - far_m);
  m(3, 2) = -1.0f;
  return m;
}

Matrix4f LookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                const Eigen::Vector3f& up) {
  // gluLookAt: the camera sits at `eye`, looks along -z towards `target`, +y as close to `up`
  // as possible. The rows of the rotation are the camera axes in world coordinates.
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f side_unnormalized = forward.cross(up);
  CALIBENCH_CHECK((target - eye).norm() > 0.0f && side_unnormalized.norm() > 1e-6f);
  const Eigen::Vector3f side = side_unnormalized.normalized();
  const Eigen::Vector3f camera_up = side.cross(forward);
  Matrix4f m = Matrix4f::Identity();
  m.block<1, 3>(0, 0) = side.transpose();
  m.block<1, 3>(1, 0) = camera_up.transpose();
  m.block<1, 3>(2, 0) = -forward.transpose();
  m(0, 3) = -side.dot(eye);
  m(1, 3) = -camera_up.dot(eye);
  m(2, 3) = forward.dot(eye);
  return m;
}

}  // namespace calibench::gfx
