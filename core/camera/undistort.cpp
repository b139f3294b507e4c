#include "core/camera/undistort.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace calibench {

UndistortedView Undistort(const CameraModel& camera, const ImageU8& image) {
  return Undistorter(camera, image.width, image.height).Apply(image);
}

Undistorter::Undistorter(const CameraModel& camera, int width, int height, double scale)
    : pinhole_(camera),
      width_(width > 0 ? width : camera.width),
      height_(height > 0 ? height : camera.height) {
  CALIBENCH_CHECK(scale > 0.0 && scale <= 1.0);
  pinhole_.type = CameraModelType::kPinholeRadTan;
  pinhole_.distortion.assign(5, 0.0);
  if (camera.type == CameraModelType::kKannalaBrandt) {
    const double focal = 0.5 * camera.width / std::tan(60.0 * kDegToRad);
    pinhole_.fx = focal;
    pinhole_.fy = focal * camera.fy / camera.fx;
  }
  // Scaled about pixel corners: pixel centres at integers, so (c + 0.5)·s − 0.5.
  pinhole_.fx *= scale;
  pinhole_.fy *= scale;
  pinhole_.cx = (pinhole_.cx + 0.5) * scale - 0.5;
  pinhole_.cy = (pinhole_.cy + 0.5) * scale - 0.5;
  pinhole_.width = std::max(1, static_cast<int>(std::lround(width_ * scale)));
  pinhole_.height = std::max(1, static_cast<int>(std::lround(height_ * scale)));
  // For every target pixel: the pinhole ray, projected through the real lens model.
  const int tw = pinhole_.width, th = pinhole_.height;
  map_x_.resize(static_cast<size_t>(tw) * th);
  map_y_.resize(map_x_.size());
  for (int v = 0; v < th; ++v) {
    for (int u = 0; u < tw; ++u) {
      const Vec3 ray((u - pinhole_.cx) / pinhole_.fx, (v - pinhole_.cy) / pinhole_.fy, 1.0);
      const auto source = camera.Project(ray);
      const size_t at = static_cast<size_t>(v) * tw + u;
      map_x_[at] = source ? static_cast<float>(source->x()) : -1.0f;
      map_y_[at] = source ? static_cast<float>(source->y()) : -1.0f;
    }
  }
}

UndistortedView Undistorter::Apply(const ImageU8& image) const {
  CALIBENCH_CHECK(image.width == width_ && image.height == height_);
  UndistortedView view;
  view.pinhole = pinhole_;
  const cv::Mat map_x(pinhole_.height, pinhole_.width, CV_32F, const_cast<float*>(map_x_.data()));
  const cv::Mat map_y(pinhole_.height, pinhole_.width, CV_32F, const_cast<float*>(map_y_.data()));
  const cv::Mat input(image.height, image.width, CV_8UC(image.channels),
                      const_cast<std::uint8_t*>(image.data.data()));
  cv::Mat output;
  cv::remap(input, output, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  view.image.width = output.cols;
  view.image.height = output.rows;
  view.image.channels = image.channels;
  view.image.data.assign(output.data, output.data + output.total() * output.elemSize());
  return view;
}

}  // namespace calibench
