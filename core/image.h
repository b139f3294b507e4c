// A plain 8-bit image type so that OpenCV stays out of widely included headers.
#pragma once

#include <cstdint>
#include <filesystem>
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

// Loads any image OpenCV reads (palette PNGs become BGR). Throws IoError naming the file.
ImageU8 LoadImage(const std::filesystem::path& path);
// Area-averaged downscale (or plain copy when already small) to at most max_width pixels wide,
// keeping the aspect ratio; for thumbnails.
ImageU8 ResizeImage(const ImageU8& image, int max_width);
// Writes PNG/JPG by extension. Throws IoError naming the file.
void SaveImage(const std::filesystem::path& path, const ImageU8& image);

}  // namespace calibench
