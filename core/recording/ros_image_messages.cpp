// sensor_msgs/Image and CompressedImage into 8-bit BGR or grey pictures
// (core/recording/ros_messages.h).
#include <bit>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/io/image_io.h"
#include "core/recording/ros_message_cursor.h"
#include "core/recording/ros_messages.h"

namespace calibench {
namespace {
// The cursor over a message and its checks: core/recording/ros_message_cursor.h.
using ros_detail::Bad;
using ros_detail::ByteSwapped;
using ros_detail::CheckRows;
using ros_detail::MessageCursor;
using ros_detail::ReadHeader;

ImageU8 FromMat(const cv::Mat& mat) {
  ImageU8 image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.channels = mat.channels();
  const std::size_t row_bytes = static_cast<std::size_t>(mat.cols) * mat.channels();
  image.data.resize(row_bytes * mat.rows);
  for (int row = 0; row < mat.rows; ++row)
    std::memcpy(image.data.data() + row * row_bytes, mat.ptr(row), row_bytes);
  return image;
}

// 16-bit grey scaled so that the image's largest value becomes 255: a 12-bit camera's data in
// 16-bit words would otherwise be a black picture after a plain shift.
cv::Mat ScaledToEightBits(const cv::Mat& sixteen) {
  double largest = 0;
  cv::minMaxLoc(sixteen, nullptr, &largest);
  cv::Mat eight;
  sixteen.convertTo(eight, CV_8U, largest > 0 ? 255.0 / largest : 1.0);
  return eight;
}

struct RawEncoding {
  const char* name;
  int cv_type;
  int conversion;  // cv::COLOR_*, or -1 to keep the pixels as they are
};
// cv_bridge's table for the Bayer patterns: ROS names the first 2x2 block from the top left,
// OpenCV names the second row's pair, hence rggb -> BayerBG.
constexpr RawEncoding kRawEncodings[] = {
    {"mono8", CV_8UC1, -1},
    {"8UC1", CV_8UC1, -1},
    {"mono16", CV_16UC1, -1},
    {"16UC1", CV_16UC1, -1},
    {"bgr8", CV_8UC3, -1},
    {"8UC3", CV_8UC3, -1},
    {"rgb8", CV_8UC3, cv::COLOR_RGB2BGR},
    {"bgra8", CV_8UC4, cv::COLOR_BGRA2BGR},
    {"rgba8", CV_8UC4, cv::COLOR_RGBA2BGR},
    {"bayer_rggb8", CV_8UC1, cv::COLOR_BayerBG2BGR},
    {"bayer_bggr8", CV_8UC1, cv::COLOR_BayerRG2BGR},
    {"bayer_gbrg8", CV_8UC1, cv::COLOR_BayerGR2BGR},
    {"bayer_grbg8", CV_8UC1, cv::COLOR_BayerGB2BGR},
    {"yuv422", CV_8UC2, cv::COLOR_YUV2BGR_UYVY},
    {"uyvy", CV_8UC2, cv::COLOR_YUV2BGR_UYVY},
    {"yuv422_yuy2", CV_8UC2, cv::COLOR_YUV2BGR_YUYV},
    {"yuyv", CV_8UC2, cv::COLOR_YUV2BGR_YUYV},
};

std::string KnownEncodings() {
  std::string names;
  for (const RawEncoding& encoding : kRawEncodings)
    names += (names.empty() ? "" : ", ") + std::string(encoding.name);
  return names;
}

}  // namespace

ImageMessage DecodeImage(std::span<const std::uint8_t> data, MessageEncoding encoding,
                         const LoadLimits& limits) {
  MessageCursor cursor(data, encoding, "Image");
  ImageMessage message;
  message.header = ReadHeader(cursor, encoding);
  const std::uint32_t height = cursor.Read<std::uint32_t>();
  const std::uint32_t width = cursor.Read<std::uint32_t>();
  message.encoding = cursor.String("the encoding");
  const bool big_endian = cursor.Read<std::uint8_t>() != 0;
  const std::uint32_t step = cursor.Read<std::uint32_t>();
  const std::span<const std::uint8_t> pixels = cursor.ByteSequence("the pixel data");
  const RawEncoding* raw = nullptr;
  for (const RawEncoding& candidate : kRawEncodings)
    if (message.encoding == candidate.name) raw = &candidate;
  if (!raw)
    Bad("Image: encoding '" + message.encoding + "' is not one Calibench reads (" +
        KnownEncodings() + ")");
  const std::uint64_t pixel_count = static_cast<std::uint64_t>(width) * height;
  if (pixel_count > static_cast<std::uint64_t>(limits.max_image_pixels))
    Bad("Image: " + std::to_string(width) + " x " + std::to_string(height) +
        " pixels is over the limit of " + std::to_string(limits.max_image_pixels) +
        " (max_image_pixels)");
  if (width == 0 || height == 0 || width > 1u << 20 || height > 1u << 20)
    Bad("Image: size " + std::to_string(width) + " x " + std::to_string(height));
  CheckRows("Image", "step", step, "a row of width x pixel size",
            static_cast<std::uint64_t>(width) * CV_ELEM_SIZE(raw->cv_type), height, pixels.size());
  cv::Mat view(static_cast<int>(height), static_cast<int>(width), raw->cv_type,
               const_cast<std::uint8_t*>(pixels.data()), step);
  cv::Mat converted = view;
  if (CV_MAT_DEPTH(raw->cv_type) == CV_16U) {
    cv::Mat native = view.clone();
    if (big_endian != (std::endian::native == std::endian::big))
      for (int row = 0; row < native.rows; ++row)
        for (auto& value : std::span(native.ptr<std::uint16_t>(row), native.cols))
          value = ByteSwapped(value);
    converted = ScaledToEightBits(native);
  } else if (raw->conversion >= 0) {
    cv::cvtColor(view, converted, raw->conversion);
  }
  message.image = FromMat(converted);
  return message;
}

ImageMessage DecodeCompressedImage(std::span<const std::uint8_t> data, MessageEncoding encoding,
                                   const LoadLimits& limits) {
  MessageCursor cursor(data, encoding, "CompressedImage");
  ImageMessage message;
  message.header = ReadHeader(cursor, encoding);
  message.encoding = cursor.String("the format");
  const std::span<const std::uint8_t> bytes = cursor.ByteSequence("the compressed data");
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  try {
    const ImageHeader header = ReadImageHeader("CompressedImage", text);
    CheckLoadLimit("CompressedImage", "pixel count", header.Pixels(), limits.max_image_pixels,
                   "max_image_pixels");
  } catch (const IoError& error) {
    Bad(error.what());
  }
  const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                        const_cast<std::uint8_t*>(bytes.data()));
  cv::Mat decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
  if (decoded.empty()) Bad("CompressedImage: the " + message.encoding + " data does not decode");
  if (decoded.depth() == CV_16U)
    decoded = ScaledToEightBits(decoded.channels() == 1 ? decoded : decoded.reshape(1));
  if (decoded.channels() == 4) cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
  if (decoded.depth() != CV_8U || (decoded.channels() != 1 && decoded.channels() != 3))
    Bad("CompressedImage: pixels of a kind Calibench does not read");
  message.image = FromMat(decoded);
  return message;
}

}  // namespace calibench
