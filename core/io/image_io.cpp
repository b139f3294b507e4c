#include "core/io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

#include "core/base/types.h"

namespace calibench {

namespace {

std::uint32_t BigEndian32(std::string_view bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) |
         b[3];
}
std::uint16_t BigEndian16(std::string_view bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return static_cast<std::uint16_t>((b[0] << 8) | b[1]);
}
std::int32_t LittleEndian32(std::string_view bytes, size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return static_cast<std::int32_t>(std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) |
                                   (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[3]} << 24));
}

[[noreturn]] void Refuse(const std::filesystem::path& path, const std::string& problem) {
  throw IoError("cannot read image '" + path.string() + "': " + problem);
}

// JPEG: the frame header (SOF0..SOF15 but DHT, JPG and DAC) holds the size; markers before it
// are skipped by their lengths.
bool JpegSize(std::string_view bytes, ImageHeader* header) {
  size_t at = 2;
  while (at + 9 <= bytes.size()) {
    if (static_cast<unsigned char>(bytes[at]) != 0xFF) return false;
    const auto marker = static_cast<unsigned char>(bytes[at + 1]);
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xD8 || (marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) {
      at += 2;  // markers without a length
      continue;
    }
    const bool frame =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      header->height = BigEndian16(bytes, at + 5);
      header->width = BigEndian16(bytes, at + 7);
      return true;
    }
    at += 2 + BigEndian16(bytes, at + 2);
  }
  return false;
}

}  // namespace

ImageHeader ReadImageHeader(const std::filesystem::path& path, std::string_view bytes) {
  ImageHeader header;
  if (bytes.size() >= 24 && bytes.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8)) {
    if (bytes.substr(12, 4) != "IHDR") Refuse(path, "a PNG without its IHDR header");
    header.format = "PNG";
    header.width = BigEndian32(bytes, 16);
    header.height = BigEndian32(bytes, 20);
  } else if (bytes.size() >= 4 && bytes.substr(0, 2) == "\xFF\xD8") {
    header.format = "JPEG";
    if (!JpegSize(bytes, &header)) Refuse(path, "a JPEG without a frame header");
  } else if (bytes.size() >= 26 && bytes.substr(0, 2) == "BM") {
    header.format = "BMP";
    header.width = LittleEndian32(bytes, 18);
    header.height = std::abs(static_cast<std::int64_t>(LittleEndian32(bytes, 22)));
  } else {
    Refuse(path, "not a PNG, JPEG or BMP file");
  }
  // PNG allows sides up to 2^31 - 1, JPEG 65535, BMP 2^31: anything wider is a broken header
  // (and the product of two such sides would overflow).
  constexpr std::int64_t kMaxSide = (std::int64_t{1} << 31) - 1;
  if (header.width > kMaxSide || header.height > kMaxSide)
    Refuse(path, std::string("the ") + header.format + " header gives a side beyond 2^31 - 1 (" +
                     std::to_string(header.width) + "x" + std::to_string(header.height) + ")");
  if (header.width <= 0 || header.height <= 0)
    Refuse(path, std::string("the ") + header.format + " header gives no size (" +
                     std::to_string(header.width) + "x" + std::to_string(header.height) + ")");
  return header;
}

std::string ReadImageFile(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) Refuse(path, "no such file");
  if (error) Refuse(path, error.message());
  if (!std::filesystem::is_regular_file(status))
    Refuse(path, "not a regular file (a folder, a FIFO or a device?)");
  std::ifstream in(path, std::ios::binary);
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!in || error) Refuse(path, "cannot open it for reading");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) Refuse(path, "read error");
  return bytes;
}

ImageU8 LoadImage(const std::filesystem::path& path, const LoadLimits& limits) {
  const std::string bytes = ReadImageFile(path);
  const ImageHeader header = ReadImageHeader(path, bytes);
  CheckLoadLimit(path,
                 (std::string(header.format) + " pixels (" + std::to_string(header.width) + "x" +
                  std::to_string(header.height) + ")")
                     .c_str(),
                 header.Pixels(), limits.max_image_pixels, "max_image_pixels");
  // IMREAD_COLOR: palette, grey and 16-bit files all arrive as 8-bit BGR, so callers see one
  // layout whatever the camera driver wrote. The decoder writes into the image's own buffer when
  // the header's size holds (cv::Mat::create keeps a buffer of the right size and type).
  ImageU8 image;
  image.width = static_cast<int>(header.width);
  image.height = static_cast<int>(header.height);
  image.channels = 3;
  image.data.resize(static_cast<size_t>(header.Pixels()) * 3);
  cv::Mat mat(image.height, image.width, CV_8UC3, image.data.data());
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                          const_cast<char*>(bytes.data()));
    cv::imdecode(encoded, cv::IMREAD_COLOR, &mat);
  } catch (const cv::Exception& e) {
    Refuse(path, e.err);
  }
  if (mat.empty()) Refuse(path, std::string("the ") + header.format + " data does not decode");
  if (mat.data == image.data.data()) return image;
  // Decoded elsewhere (a JPEG rotated by its EXIF orientation): copy what the decoder gave.
  image.width = mat.cols;
  image.height = mat.rows;
  image.data.resize(mat.total() * 3);
  const size_t row_bytes = static_cast<size_t>(mat.cols) * 3;
  for (int y = 0; y < mat.rows; ++y) std::memcpy(image.Row(y), mat.ptr<std::uint8_t>(y), row_bytes);
  return image;
}

namespace {

void CheckWritable(const ImageU8& image, const std::string& what) {
  const bool consistent =
      image.width > 0 && image.height > 0 &&
      (image.channels == 1 || image.channels == 3 || image.channels == 4) &&
      image.data.size() == static_cast<size_t>(image.width) * image.height * image.channels;
  if (!consistent) {
    throw IoError("cannot write image '" + what + "': the image is empty or its size (" +
                  std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                  std::to_string(image.channels) + ") does not match its data");
  }
}

}  // namespace

std::string EncodeImage(const ImageU8& image, const std::string& extension) {
  CheckWritable(image, "in memory as " + extension);
  const cv::Mat mat(image.height, image.width, CV_8UC(image.channels),
                    const_cast<std::uint8_t*>(image.data.data()));
  std::vector<std::uint8_t> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(extension, mat, bytes);
  } catch (const cv::Exception& e) {
    throw IoError("cannot encode an image as '" + extension + "': " + e.err);
  }
  if (!encoded) throw IoError("cannot encode an image as '" + extension + "'");
  return std::string(bytes.begin(), bytes.end());
}

void SaveImage(const std::filesystem::path& path, const ImageU8& image) {
  CheckWritable(image, path.string());
  // A header over the caller's pixels; imwrite only reads them.
  const cv::Mat mat(image.height, image.width, CV_8UC(image.channels),
                    const_cast<std::uint8_t*>(image.data.data()));
  bool written = false;
  std::string reason = "OpenCV could not write it (missing folder or no permission?)";
  try {
    written = cv::imwrite(path.string(), mat);
  } catch (const cv::Exception& e) {
    reason = e.err;  // e.g. an extension no encoder handles
  }
  if (!written) throw IoError("cannot write image '" + path.string() + "': " + reason);
}

ImageU8 ResizeImage(const ImageU8& image, int max_width) {
  if (image.empty() || image.width <= max_width) return image;
  const cv::Mat source(image.height, image.width, CV_8UC(image.channels),
                       const_cast<std::uint8_t*>(image.data.data()));
  const int height = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.height) *
                                                              max_width / image.width)));
  cv::Mat resized;
  cv::resize(source, resized, cv::Size(max_width, height), 0, 0, cv::INTER_AREA);
  ImageU8 out;
  out.width = resized.cols;
  out.height = resized.rows;
  out.channels = image.channels;
  out.data.assign(resized.data, resized.data + resized.total() * resized.elemSize());
  return out;
}

}  // namespace calibench
