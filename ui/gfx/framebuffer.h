// An offscreen render target (RGBA8 colour texture + 24-bit depth). Every view renders into one;
// the window shows its texture, the headless path reads it back: that is what makes a headless
// render identical to the on-screen one.
#pragma once

#include <cstdint>

#include "core/base/image.h"

namespace calibench::gfx {

class Framebuffer {
 public:
  Framebuffer() = default;
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  // (Re)allocates when the size changes. Requires a current context.
  void Resize(int width, int height);
  // Binds for drawing and sets the viewport to the whole target.
  void Bind() const;
  static void BindDefault(int window_width, int window_height);
  void Clear(float r, float g, float b, float a) const;

  // Top row first (flipped from GL's bottom-up order), 3 channels BGR like ImageU8 elsewhere.
  ImageU8 ReadPixels() const;
  // The same from the window's default framebuffer (its back buffer: call before swapping), for
  // screenshots of the whole window, ImGui included. Sizes in framebuffer pixels.
  static ImageU8 ReadDefaultPixels(int window_width, int window_height);
  // Copies the colour into the window's default framebuffer (its back buffer), pixel for pixel
  // from the lower-left corner: how a window shows a frame drawn offscreen.
  void BlitToDefault() const;
  // The colour texture, bottom row first as GL stores it: show it with ImGui::Image(texture,
  // size, ImVec2(0, 1), ImVec2(1, 0)) to see it upright.
  std::uint32_t color_texture() const { return color_texture_; }
  std::uint32_t framebuffer() const { return framebuffer_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void Release();
  std::uint32_t framebuffer_ = 0, color_texture_ = 0, depth_buffer_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace calibench::gfx
