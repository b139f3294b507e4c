// What a view's offscreen picture shows, hashed (a 64-bit mix over the bytes of everything it
// depends on): the 3D views redraw their framebuffer only when the key changes, since drawing a
// large cloud on a software renderer costs most of a frame.
#pragma once

#include <cstddef>
#include <cstdint>

namespace calibench::ui {

class FrameKey {
 public:
  // seed: what the picture is of (e.g. the uploaded cloud's key).
  explicit FrameKey(std::uint64_t seed) : key_(seed ^ 0xcbf29ce484222325ull) {}
  void Mix(const void* data, size_t bytes);
  std::uint64_t value() const { return key_; }

 private:
  std::uint64_t key_;
};

}  // namespace calibench::ui
