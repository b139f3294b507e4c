#include "ui/gfx/renderers.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/base/types.h"
#include "ui/gfx/gl_api.h"
#include "ui/gfx/shader.h"
#include "ui/gfx/shader_sources.h"

namespace calibench::gfx {
namespace {

// Positions go to GL straight from the std::vector, so the element layouts must be packed.
static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
static_assert(sizeof(Rgba) == 4);

// The vertex layout shared by points, lines and triangles: location 0 = vec3 position,
// location 1 = RGBA8 colour normalized to [0, 1].
void CreateColoredVertexArray(std::uint32_t* vao, std::uint32_t* vbo_positions,
                              std::uint32_t* vbo_colors) {
  glGenVertexArrays(1, vao);
  glBindVertexArray(*vao);
  glGenBuffers(1, vbo_positions);
  glBindBuffer(GL_ARRAY_BUFFER, *vbo_positions);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Eigen::Vector3f), nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, vbo_colors);
  glBindBuffer(GL_ARRAY_BUFFER, *vbo_colors);
  glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Rgba), nullptr);
  glEnableVertexAttribArray(1);
  glBindVertexArray(0);
}

// Returns the vertex count. `group` is 1 (points), 2 (line segments) or 3 (triangles).
size_t UploadColored(std::uint32_t vbo_positions, std::uint32_t vbo_colors,
                     const std::vector<Eigen::Vector3f>& positions, const std::vector<Rgba>& colors,
                     size_t group, const char* what) {
  if (positions.size() != colors.size() || positions.size() % group != 0) {
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(positions.size()) +
                                " vertices and " + std::to_string(colors.size()) +
                                " colours; need equal counts, a multiple of " +
                                std::to_string(group));
  }
  glBindBuffer(GL_ARRAY_BUFFER, vbo_positions);
  glBufferData(GL_ARRAY_BUFFER, positions.size() * sizeof(Eigen::Vector3f), positions.data(),
               GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_colors);
  glBufferData(GL_ARRAY_BUFFER, colors.size() * sizeof(Rgba), colors.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return positions.size();
}

void DeleteColored(std::uint32_t program, std::uint32_t vao, std::uint32_t vbo_positions,
                   std::uint32_t vbo_colors) {
  if (program) glDeleteProgram(program);
  if (vao) glDeleteVertexArrays(1, &vao);
  if (vbo_positions) glDeleteBuffers(1, &vbo_positions);
  if (vbo_colors) glDeleteBuffers(1, &vbo_colors);
}

// Sets all the state a colour draw depends on (ImGui and other views leave theirs behind).
// Depth writes off lets translucent surfaces show what lies behind them whatever the draw order.
void PrepareColoredDraw(std::uint32_t program, const Matrix4f& view_projection, bool depth_write) {
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "view_projection"), 1, GL_FALSE,
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
}

void FinishDraw() {
  glBindVertexArray(0);
  glUseProgram(0);
  glDepthMask(GL_TRUE);
}

}  // namespace

PointRenderer::PointRenderer() {
  program_ = BuildProgram("points", shader_sources::kPointsVert, shader_sources::kPointsFrag);
  CreateColoredVertexArray(&vao_, &vbo_positions_, &vbo_colors_);
}

PointRenderer::~PointRenderer() { DeleteColored(program_, vao_, vbo_positions_, vbo_colors_); }

void PointRenderer::Upload(const std::vector<Eigen::Vector3f>& positions,
                           const std::vector<Rgba>& colors) {
  count_ = UploadColored(vbo_positions_, vbo_colors_, positions, colors, 1, "PointRenderer");
}

void PointRenderer::Draw(const Matrix4f& view_projection, float point_size_px,
                         float opacity) const {
  if (count_ == 0) return;
  // Translucent points must not hide each other, opaque ones must.
  PrepareColoredDraw(program_, view_projection, opacity >= 1.0f);
  glUniform1f(glGetUniformLocation(program_, "point_size_px"), point_size_px);
  glUniform1f(glGetUniformLocation(program_, "opacity"), std::clamp(opacity, 0.0f, 1.0f));
  glEnable(GL_PROGRAM_POINT_SIZE);  // size from gl_PointSize in the vertex shader
  glBindVertexArray(vao_);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(count_));
  FinishDraw();
}

LineRenderer::LineRenderer() {
  program_ = BuildProgram("lines", shader_sources::kColoredVert, shader_sources::kColoredFrag);
  CreateColoredVertexArray(&vao_, &vbo_positions_, &vbo_colors_);
}

LineRenderer::~LineRenderer() { DeleteColored(program_, vao_, vbo_positions_, vbo_colors_); }

void LineRenderer::Upload(const std::vector<Eigen::Vector3f>& vertices,
                          const std::vector<Rgba>& colors) {
  count_ = UploadColored(vbo_positions_, vbo_colors_, vertices, colors, 2, "LineRenderer");
}

void LineRenderer::Draw(const Matrix4f& view_projection, float width_px) const {
  if (count_ == 0) return;
  PrepareColoredDraw(program_, view_projection, true);
  // Wide lines are deprecated in core profile: a forward-compatible context (macOS) rejects
  // widths above 1 and drivers clamp to GL_ALIASED_LINE_WIDTH_RANGE (Mesa: up to 255, NVIDIA:
  // about 10). So width_px is a wish that may be ignored; views must not rely on it.
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  GLfloat range[2] = {1.0f, 1.0f};
  glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, range);
  const bool forward_compatible = (flags & GL_CONTEXT_FLAG_FORWARD_COMPATIBLE_BIT) != 0;
  glLineWidth(forward_compatible ? 1.0f : std::clamp(width_px, range[0], range[1]));
  glBindVertexArray(vao_);
  glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(count_));
  glLineWidth(1.0f);
  FinishDraw();
}

TriangleRenderer::TriangleRenderer() {
  program_ = BuildProgram("triangles", shader_sources::kColoredVert, shader_sources::kColoredFrag);
  CreateColoredVertexArray(&vao_, &vbo_positions_, &vbo_colors_);
}

TriangleRenderer::~TriangleRenderer() {
  DeleteColored(program_, vao_, vbo_positions_, vbo_colors_);
}

void TriangleRenderer::Upload(const std::vector<Eigen::Vector3f>& vertices,
                              const std::vector<Rgba>& colors) {
  count_ = UploadColored(vbo_positions_, vbo_colors_, vertices, colors, 3, "TriangleRenderer");
}

void TriangleRenderer::Draw(const Matrix4f& view_projection) const {
  if (count_ == 0) return;
  // Depth test on (points behind a board quad are tinted by it), depth write off (the quad hides
  // nothing drawn after it, and two quads blend whatever their order).
  PrepareColoredDraw(program_, view_projection, false);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(count_));
  FinishDraw();
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
