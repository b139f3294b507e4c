#include "core/targetless/check_overlay.h"

#include <opencv2/imgproc.hpp>

namespace calibench {

ImageU8 DrawEdgeOverlay(const ImageU8& image, const std::vector<SceneEdgePoint>& lidar_edges,
                        const CameraModel& camera, const std::vector<OverlayPose>& poses,
                        const std::vector<std::string>& caption) {
  cv::Mat wrapped(image.height, image.width, image.channels == 3 ? CV_8UC3 : CV_8UC1,
                  const_cast<std::uint8_t*>(image.data.data()));
  cv::Mat grey, canvas;
  if (image.channels == 3)
    cv::cvtColor(wrapped, grey, cv::COLOR_BGR2GRAY);
  else
    grey = wrapped;
  cv::Mat dimmed = grey * 0.6;
  cv::cvtColor(dimmed, canvas, cv::COLOR_GRAY2BGR);
  const int radius = std::max(1, image.width / 800);
  for (const OverlayPose& pose : poses) {
    for (const SceneEdgePoint& edge : lidar_edges) {
      const auto pixel = camera.Project(pose.cam_from_lidar * edge.point);
      if (!pixel || !camera.InImage(*pixel)) continue;
      cv::circle(canvas,
                 cv::Point(static_cast<int>(std::lround(pixel->x())),
                           static_cast<int>(std::lround(pixel->y()))),
                 radius, cv::Scalar(pose.b, pose.g, pose.r), cv::FILLED, cv::LINE_AA);
    }
  }
  if (!caption.empty()) {
    const double scale = std::max(0.5, image.width / 1600.0);
    const int line_px = static_cast<int>(std::lround(34 * scale));
    cv::rectangle(canvas,
                  cv::Rect(0, 0, canvas.cols, line_px * static_cast<int>(caption.size()) + 12),
                  cv::Scalar(20, 20, 20), cv::FILLED);
    for (size_t i = 0; i < caption.size(); ++i)
      cv::putText(canvas, caption[i], cv::Point(12, line_px * static_cast<int>(i + 1)),
                  cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale, cv::Scalar(235, 235, 235),
                  std::max(1, static_cast<int>(scale * 2)), cv::LINE_AA);
  }
  ImageU8 out{canvas.cols, canvas.rows, 3, {}};
  out.data.assign(canvas.data, canvas.data + canvas.total() * 3);
  return out;
}

}  // namespace calibench
