// Image files: reading (any format OpenCV decodes), writing PNG/JPG, thumbnails.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/base/image.h"
#include "core/io/load_limits.h"

namespace calibench {

// The format and size an image file declares in its header, read without decoding.
struct ImageHeader {
  const char* format = "";  // "PNG", "JPEG" or "BMP"
  std::int64_t width = 0;
  std::int64_t height = 0;
  std::int64_t Pixels() const { return width * height; }
};
// Throws IoError naming the file for any other format, or a header that does not give a size.
// PNG, JPEG and BMP are what cameras and their drivers write; the other decoders OpenCV carries
// (JPEG 2000, TIFF, OpenEXR, ...) are never run on users' files.
ImageHeader ReadImageHeader(const std::filesystem::path& path, std::string_view bytes);

// Reads a whole regular file (FIFOs and devices refused). Throws IoError naming the file.
std::string ReadImageFile(const std::filesystem::path& path);

// Loads a PNG, JPEG or BMP as 8-bit BGR (grey, palette and 16-bit files too). The size is checked
// against limits.max_image_pixels from the header, then the pixels are decoded straight into the
// returned image (no second copy). Throws IoError naming the file.
ImageU8 LoadImage(const std::filesystem::path& path, const LoadLimits& limits = {});
// Area-averaged downscale (or plain copy when already small) to at most max_width pixels wide,
// keeping the aspect ratio; for thumbnails.
ImageU8 ResizeImage(const ImageU8& image, int max_width);
// Writes PNG/JPG by extension. Throws IoError naming the file.
void SaveImage(const std::filesystem::path& path, const ImageU8& image);
// The image as the bytes of a file of that type (extension ".png" or ".jpg"; channels as
// SaveImage takes them). Throws IoError when the image is inconsistent or cannot be encoded.
std::string EncodeImage(const ImageU8& image, const std::string& extension);

}  // namespace calibench
