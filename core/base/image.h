// A plain 8-bit image type so that OpenCV stays out of widely included headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace calibench {

// Row-major, interleaved channels (1 = grey, 3 = BGR as OpenCV stores them).
struct ImageU8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::uint8_t> data;

  bool empty() const { return data.empty(); }
  std::uint8_t* Row(int y) { return data.data() + static_cast<size_t>(y) * width * channels; }
  const std::uint8_t* Row(int y) const {
    return data.data() + static_cast<size_t>(y) * width * channels;
  }
};

}  // namespace calibench
