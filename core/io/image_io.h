// Image files: reading (any format OpenCV decodes), writing PNG/JPG, thumbnails.
#pragma once

#include <filesystem>

#include "core/base/image.h"

namespace calibench {

// Loads any image OpenCV reads (palette PNGs become BGR). Throws IoError naming the file.
ImageU8 LoadImage(const std::filesystem::path& path);
// Area-averaged downscale (or plain copy when already small) to at most max_width pixels wide,
// keeping the aspect ratio; for thumbnails.
ImageU8 ResizeImage(const ImageU8& image, int max_width);
// Writes PNG/JPG by extension. Throws IoError naming the file.
void SaveImage(const std::filesystem::path& path, const ImageU8& image);

}  // namespace calibench
