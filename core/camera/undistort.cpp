#include "core/camera/undistort.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace calibench {

UndistortedView Undistort(const CameraModel& camera, const ImageU8& image) {
  UndistortedView view;
  view.pinhole = camera;
  view.pinhole.type = CameraModelType::kPinholeRadTan;
  view.pinhole.distortion.assign(5, 0.0);
  if (camera.type == CameraModelType::kKannalaBrandt) {
    const double focal = 0.5 * camera.width / std::tan(60.0 * kDegToRad);
    view.pinhole.fx = focal;
    view.pinhole.fy = focal * camera.fy / camera.fx;
  }
  // For every target pixel: the pinhole ray, projected through the real lens model.
  cv::Mat map_x(image.height, image.width, CV_32F), map_y(image.height, image.width, CV_32F);
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      const Vec3 ray((u - view.pinhole.cx) / view.pinhole.fx,
                     (v - view.pinhole.cy) / view.pinhole.fy, 1.0);
      const auto source = camera.Project(ray);
      map_x.at<float>(v, u) = source ? static_cast<float>(source->x()) : -1.0f;
      map_y.at<float>(v, u) = source ? static_cast<float>(source->y()) : -1.0f;
    }
  }
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
