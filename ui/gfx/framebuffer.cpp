#include "ui/gfx/framebuffer.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ui/gfx/gl_api.h"
#include "ui/gfx/texture_versions.h"

namespace calibench::gfx {
namespace {

// Restores the bindings Resize() disturbs, so that resizing a view in the middle of drawing
// another leaves the other one bound.
class BindingGuard {
 public:
  BindingGuard() {
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_framebuffer_);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_framebuffer_);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture_);
    glGetIntegerv(GL_RENDERBUFFER_BINDING, &renderbuffer_);
  }
  ~BindingGuard() {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(draw_framebuffer_));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(read_framebuffer_));
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(texture_));
    glBindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(renderbuffer_));
  }

 private:
  GLint draw_framebuffer_ = 0, read_framebuffer_ = 0, texture_ = 0, renderbuffer_ = 0;
};

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// Reads colour buffer `buffer` of `framebuffer` (0: the window's) as BGR, top row first.
ImageU8 ReadBgrTopRowFirst(GLuint framebuffer, GLenum buffer, int width, int height) {
  ImageU8 image;
  image.width = width;
  image.height = height;
  image.channels = 3;
  image.data.resize(static_cast<size_t>(width) * height * 3);
  GLint previous_read = 0, previous_read_buffer = 0, previous_alignment = 0,
        previous_row_length = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &previous_read);
  glGetIntegerv(GL_PACK_ALIGNMENT, &previous_alignment);
  glGetIntegerv(GL_PACK_ROW_LENGTH, &previous_row_length);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glGetIntegerv(GL_READ_BUFFER, &previous_read_buffer);
  glReadBuffer(buffer);
  // Rows of 3 * width bytes are not 4-byte aligned for odd widths.
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, width, height, GL_BGR, GL_UNSIGNED_BYTE, image.data.data());
  glPixelStorei(GL_PACK_ALIGNMENT, previous_alignment);
  glPixelStorei(GL_PACK_ROW_LENGTH, previous_row_length);
  glReadBuffer(static_cast<GLenum>(previous_read_buffer));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(previous_read));
  // GL returns the bottom row first; ImageU8 (and every image file) starts at the top.
  const size_t row_bytes = static_cast<size_t>(width) * 3;
  std::vector<std::uint8_t> swap(row_bytes);
  for (int y = 0; y < height / 2; ++y) {
    std::uint8_t* top = image.Row(y);
    std::uint8_t* bottom = image.Row(height - 1 - y);
    std::memcpy(swap.data(), top, row_bytes);
    std::memcpy(top, bottom, row_bytes);
    std::memcpy(bottom, swap.data(), row_bytes);
  }
  return image;
}

}  // namespace

Framebuffer::~Framebuffer() { Release(); }

void Framebuffer::Release() {
  if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
  if (color_texture_) glDeleteTextures(1, &color_texture_);
  if (depth_buffer_) glDeleteRenderbuffers(1, &depth_buffer_);
  framebuffer_ = color_texture_ = depth_buffer_ = 0;
  width_ = height_ = 0;
}

void Framebuffer::Resize(int width, int height) {
  if (framebuffer_ && width == width_ && height == height_) return;
  GLint max_texture = 0, max_renderbuffer = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  const int max_size = std::min(max_texture, max_renderbuffer);
  if (width <= 0 || height <= 0 || width > max_size || height > max_size) {
    throw std::invalid_argument("framebuffer size " + SizeText(width, height) + " is outside 1.." +
                                std::to_string(max_size) + " pixels");
  }
  Release();
  BindingGuard guard;
  glGenTextures(1, &color_texture_);
  glBindTexture(GL_TEXTURE_2D, color_texture_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  // Linear: the window may show the texture scaled; no mipmaps, so MIN_FILTER must not use them.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glGenRenderbuffers(1, &depth_buffer_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_buffer_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);

  glGenFramebuffers(1, &framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_texture_, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_buffer_);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    Release();
    throw std::runtime_error("framebuffer " + SizeText(width, height) +
                             " (RGBA8 + DEPTH24) is incomplete: status " + std::to_string(status));
  }
  width_ = width;
  height_ = height;
  MarkTextureChanged(color_texture_);  // a new texture (GL may reuse a deleted one's name)
}

void Framebuffer::Bind() const {
  if (!framebuffer_) throw std::logic_error("Framebuffer::Bind before Resize");
  // Bound to be drawn into: whoever shows the texture must assume new pixels.
  MarkTextureChanged(color_texture_);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glViewport(0, 0, width_, height_);
}

void Framebuffer::BindDefault(int window_width, int window_height) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, window_width, window_height);
}

void Framebuffer::Clear(float r, float g, float b, float a) const {
  Bind();
  // Clearing obeys the scissor test and the depth write mask, which other GL code (ImGui, a
  // caller's own drawing) may have left set.
  glDisable(GL_SCISSOR_TEST);
  glDepthMask(GL_TRUE);
  glClearColor(r, g, b, a);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

ImageU8 Framebuffer::ReadPixels() const {
  if (!framebuffer_) throw std::logic_error("Framebuffer::ReadPixels before Resize");
  return ReadBgrTopRowFirst(framebuffer_, GL_COLOR_ATTACHMENT0, width_, height_);
}

void Framebuffer::BlitToDefault() const {
  if (!framebuffer_) throw std::logic_error("Framebuffer::BlitToDefault before Resize");
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

ImageU8 Framebuffer::ReadDefaultPixels(int window_width, int window_height) {
  return ReadBgrTopRowFirst(0, GL_BACK, window_width, window_height);
}

}  // namespace calibench::gfx
