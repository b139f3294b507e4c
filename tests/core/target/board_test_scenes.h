// Shared scenes for the camera-side board tests: 1440x1080 pinhole and fisheye cameras, A3 boards,
// tilted board poses and exactly projected corners.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/sim/sim.h"
#include "core/target/board_camera.h"

namespace calibench::test {

constexpr double kDeg = M_PI / 180.0;

// The simulator's 1440x1080 cameras and A3 checkerboard.
inline CameraModel PinholeCamera() { return DefaultSimCamera(false); }
inline CameraModel FisheyeCamera() { return DefaultSimCamera(true); }
inline BoardSpec A3Checkerboard() { return BoardPreset("a3"); }

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
