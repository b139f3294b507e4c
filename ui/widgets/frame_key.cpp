#include "ui/widgets/frame_key.h"

#include <cstdint>
#include <cstring>

namespace calibench::ui {
namespace {

// One multiply-xorshift step per 8 bytes: the key is hashed over whole draw lists every frame
// (redraw_regions.cpp), where FNV's multiply per byte showed.
std::uint64_t MixWord(std::uint64_t key, std::uint64_t word) {
  key = (key ^ word) * 0x9E3779B97F4A7C15ull;
  return key ^ (key >> 29);
}

}  // namespace

void FrameKey::Mix(const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t word = 0;
  for (; bytes >= 8; bytes -= 8, p += 8) {
    std::memcpy(&word, p, 8);
    key_ = MixWord(key_, word);
  }
  word = 0;
  std::memcpy(&word, p, bytes);
  key_ = MixWord(key_, word ^ (static_cast<std::uint64_t>(bytes) << 56));
}

}  // namespace calibench::ui
