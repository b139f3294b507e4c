// Shared scenes for the camera-side board tests: 1440x1080 pinhole and fisheye cameras, A3 boards,
// tilted board poses and exactly projected corners.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/board_camera.h"
#include "core/geometry.h"
#include "core/sim.h"

namespace calibench::test {

constexpr double kDeg = M_PI / 180.0;

inline CameraModel PinholeCamera() {
  CameraModel c;
  c.type = CameraModelType::kPinholeRadTan;
  c.width = 1440;
  c.height = 1080;
  c.fx = c.fy = 1000.0;
  c.cx = 719.5;
  c.cy = 539.5;
  c.distortion = {-0.1, 0.05, 0.0005, -0.0003, 0.0};
  return c;
}

inline CameraModel FisheyeCamera() {
  CameraModel c;
  c.type = CameraModelType::kKannalaBrandt;
  c.width = 1440;
  c.height = 1080;
  c.fx = c.fy = 450.0;
  c.cx = 719.5;
  c.cy = 539.5;
  c.distortion = {-0.01, 0.005, -0.002, 0.0005};
  return c;
}

// A3 sheet, 7x5 inner corners, 40 mm squares.
inline BoardSpec A3Checkerboard() {
  BoardSpec b;
  b.type = BoardType::kCheckerboard;
  b.cols = 7;
  b.rows = 5;
  b.square_size = 0.04;
  b.board_width = 0.42;
  b.board_height = 0.297;
  return b;
}

inline BoardSpec A3Charuco(const std::string& dictionary) {
  BoardSpec b;
  b.type = BoardType::kCharuco;
  b.cols = 5;
  b.rows = 7;
  b.square_size = 0.04;
  b.marker_size = 0.03;
  b.dictionary = dictionary;
  b.board_width = 0.297;
  b.board_height = 0.42;
  return b;
}

// Board centre at `centre` (camera frame), print facing the camera (board z along +z_cam before
// the tilt), tilted by `tilt` about an oblique in-plane axis.
inline Pose BoardPose(const Vec3& centre, double tilt_rad) {
  Pose pose = Pose::Identity();
  pose.linear() = ExpSO3(tilt_rad * Vec3(0.8, 0.6, 0.0)) * ExpSO3(Vec3(0, 0, 0.1));
  pose.translation() = centre;
  return pose;
}

inline BoardDetection ProjectCorners(const CameraModel& camera, const BoardSpec& board,
                                     const Pose& pose) {
  BoardDetection detection;
  const std::vector<Vec3> points = BoardCornerPoints(board);
  for (size_t i = 0; i < points.size(); ++i) {
    const auto pixel = camera.Project(pose * points[i]);
    CALIBENCH_CHECK(pixel.has_value());
    detection.pixels.push_back(*pixel);
    detection.board_points.push_back(points[i]);
    detection.ids.push_back(static_cast<int>(i));
  }
  return detection;
}

inline Vec4 PlaneOf(const Pose& cam_from_board) {
  return OrientTowardsOrigin(TransformPlane(cam_from_board, Plane{Vec3::UnitZ(), 0.0}))
      .Coefficients();
}

}  // namespace calibench::test
