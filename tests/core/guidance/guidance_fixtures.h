// Shared by core/guidance's tests: a VLP-16 rig as guidance sees it, boards facing the camera, and
// the solution three frontal boards give.
#pragma once

#include <gtest/gtest.h>

#include <vector>

#include "core/estimation/fisher_information.h"
#include "core/guidance/next_pose.h"
#include "core/sim/sim.h"

namespace calibench {

// VLP-16, the simulator's camera, an A3 checkerboard, the default mount.
inline SensorGeometry Vlp16Sensors(bool fisheye = false) {
  SensorGeometry s;
  s.camera = DefaultSimCamera(fisheye);
  s.board = BoardPreset("a3");
  s.lidar = MakeBeamTable(LidarModel::kVlp16);
  s.min_distance_m = 1.0;
  s.max_distance_m = 4.0;
  s.range_sigma_m = 0.01;
  s.corner_sigma_px = 0.2;
  return s;
}

// A board facing the camera at `centre` (camera frame), turned by yaw about its vertical axis.
inline Pose FacingBoard(const Vec3& centre, double yaw_deg = 0.0) {
  const Vec3 z = centre.normalized();
  const Vec3 x = (Vec3::UnitX() - Vec3::UnitX().dot(z) * z).normalized();
  Mat3 facing;
  facing << x, z.cross(x), z;
  Pose pose = Pose::Identity();
  pose.linear() = facing * Eigen::AngleAxisd(yaw_deg * kDegToRad, Vec3::UnitY()).toRotationMatrix();
  pose.translation() = centre;
  return pose;
}

// Three boards, all frontal near the image centre (planned pairs, as the solver would see them),
// and the solution they would give: the translation along the view is well fixed, the rest
// weakly.
inline void ThreeFrontalBoards(const SensorGeometry& sensors, const Pose& cam_from_lidar,
                               const SolverOptions& solver, std::vector<PlanePair>* pairs,
                               std::vector<Pose>* seen, SolverResult* solution) {
  for (const Pose& pose : {FacingBoard(Vec3(0, 0, 1.6), 10), FacingBoard(Vec3(0.1, 0, 2.0), -10),
                           FacingBoard(Vec3(-0.1, 0.05, 2.2), 15)}) {
    BoardReturns returns;
    const Feasibility f = CheckFeasible(sensors, cam_from_lidar, pose, GuidanceOptions{}, &returns);
    ASSERT_TRUE(f.feasible) << f.why;
    pairs->push_back(PlannedPair(sensors, cam_from_lidar, pose, returns));
    seen->push_back(pose);
  }
  solution->cam_from_lidar = cam_from_lidar;
  solution->covariance = ExpectedPoseInformation(*pairs, cam_from_lidar, solver).inverse();
}

}  // namespace calibench
