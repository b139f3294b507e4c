// ImageTexture of renderers.h: ImageU8 (grey or BGR) -> GL texture -> screen-aligned rectangle.
#include <stdexcept>
#include <string>

#include "ui/gfx/gl_api.h"
#include "ui/gfx/renderers.h"
#include "ui/gfx/shader.h"
#include "ui/gfx/shader_sources.h"
#include "ui/gfx/texture_versions.h"

namespace calibench::gfx {

ImageTexture::~ImageTexture() {
  if (texture_) glDeleteTextures(1, &texture_);
  if (program_) glDeleteProgram(program_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
}

void ImageTexture::Upload(const ImageU8& image, bool linear_filtering) {
  const size_t expected = static_cast<size_t>(image.width) * image.height * image.channels;
  if ((image.channels != 1 && image.channels != 3) || image.width <= 0 || image.height <= 0 ||
      image.data.size() != expected) {
    throw std::invalid_argument("ImageTexture: need a grey or BGR ImageU8, got " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) +
                                "x" + std::to_string(image.channels) + " with " +
                                std::to_string(image.data.size()) + " bytes");
  }
  if (!texture_) glGenTextures(1, &texture_);
  GLint previous_texture = 0, previous_alignment = 0, previous_row_length = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &previous_texture);
  glGetIntegerv(GL_UNPACK_ALIGNMENT, &previous_alignment);
  glGetIntegerv(GL_UNPACK_ROW_LENGTH, &previous_row_length);
  glBindTexture(GL_TEXTURE_2D, texture_);
  // ImageU8 rows are tightly packed; GL's default assumes 4-byte aligned rows, which odd widths
  // (3 * width or width bytes) break.
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  const bool grey = image.channels == 1;
  // Rows go up top row first, so texture v = 0 is the image's top row (see image.vert.glsl).
  glTexImage2D(GL_TEXTURE_2D, 0, grey ? GL_R8 : GL_RGB8, image.width, image.height, 0,
               grey ? GL_RED : GL_BGR, GL_UNSIGNED_BYTE, image.data.data());
  // Grey is stored once and read as (g, g, g, 1) by every sampler, ImGui::Image's included.
  const GLint grey_swizzle[] = {GL_RED, GL_RED, GL_RED, GL_ONE};
  const GLint colour_swizzle[] = {GL_RED, GL_GREEN, GL_BLUE, GL_ONE};
  glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, grey ? grey_swizzle : colour_swizzle);
  const GLint filter = linear_filtering ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, previous_alignment);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, previous_row_length);
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(previous_texture));
  width_ = image.width;
  height_ = image.height;
  MarkTextureChanged(texture_);
}

void ImageTexture::Draw(float x0, float y0, float x1, float y1) const {
  if (!texture_) throw std::logic_error("ImageTexture::Draw before Upload");
  if (!program_) {
    program_ = BuildProgram("image", shader_sources::kImageVert, shader_sources::kImageFrag);
    glGenVertexArrays(1, &vao_);
    glGenBuffers(1, &vbo_);
    glBindVertexArray(vao_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float),
                          reinterpret_cast<const void*>(2 * sizeof(float)));
    glEnableVertexAttribArray(1);
  }
  // Triangle strip (x, y, u, v): bottom-left, bottom-right, top-left, top-right; the top edge
  // (y1) samples v = 0, the image's top row.
  const float vertices[] = {x0, y0, 0.0f, 1.0f, x1, y0, 1.0f, 1.0f,
                            x0, y1, 0.0f, 0.0f, x1, y1, 1.0f, 0.0f};
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof(vertices), vertices, GL_STREAM_DRAW);
  // An image is an opaque backdrop or overlay: no depth test, no blending.
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glUseProgram(program_);
  glUniform1i(glGetUniformLocation(program_, "image"), 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindTexture(GL_TEXTURE_2D, 0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace calibench::gfx
