#include "core/io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

#include "core/base/types.h"

namespace calibench {

ImageU8 LoadImage(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw IoError("cannot read image '" + path.string() + "': no such file");
  }
  // IMREAD_COLOR: palette, grey and 16-bit files all arrive as 8-bit BGR, so callers see one
  // layout whatever the camera driver wrote.
  cv::Mat mat;
  try {
    mat = cv::imread(path.string(), cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw IoError("cannot read image '" + path.string() + "': " + e.err);
  }
  if (mat.empty()) {
    throw IoError("cannot read image '" + path.string() + "': not an image format OpenCV decodes");
  }
  ImageU8 image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.channels = mat.channels();
  image.data.resize(static_cast<size_t>(mat.rows) * mat.cols * mat.channels());
  const size_t row_bytes = static_cast<size_t>(mat.cols) * mat.channels();
  for (int y = 0; y < mat.rows; ++y) std::memcpy(image.Row(y), mat.ptr<std::uint8_t>(y), row_bytes);
  return image;
}

void SaveImage(const std::filesystem::path& path, const ImageU8& image) {
  const bool consistent =
      image.width > 0 && image.height > 0 &&
      (image.channels == 1 || image.channels == 3 || image.channels == 4) &&
      image.data.size() == static_cast<size_t>(image.width) * image.height * image.channels;
  if (!consistent) {
    throw IoError("cannot write image '" + path.string() + "': the image is empty or its size (" +
                  std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                  std::to_string(image.channels) + ") does not match its data");
  }
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
