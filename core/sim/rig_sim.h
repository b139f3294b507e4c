// A simulated rig of one LiDAR and two cameras written in the rig's folder form
// (core/io/rig_folder.h): camera 0 as SimulateDataset's camera, camera 1 turned aside so that the
// two fields overlap partly. Each capture's board is placed for one camera (alternating, as a
// user walks along the rig) and every camera that sees it whole writes its frame.
#pragma once

#include <filesystem>
#include <vector>

#include "core/sim/sim.h"

namespace calibench {

struct RigSimOptions {
  SimOptions base;  // the LiDAR, the board, the noise, camera 0 and its cam_from_lidar
  // Camera 1: its model (empty width = the simulator's fisheye) and how far it is turned to the
  // left of camera 0 about the LiDAR's z axis (degrees), 20 cm to the left.
  CameraModel second_camera;
  double second_camera_yaw_deg = 60.0;
  int num_captures = 24;
  bool Check(std::string* why) const;
};

struct RigSimTruth {
  std::vector<Pose> cam_from_lidar;  // per camera
  int shared_captures = 0;           // captures both cameras have a frame of
};

// Writes clouds/NNNN.pcd, images/cam0|cam1/NNNN.png, cameras/cam0.yaml, cameras/cam1.yaml and
// target.json under out_dir. Throws std::invalid_argument for options that fail Check, IoError on
// write failures, std::runtime_error when a capture cannot be placed.
RigSimTruth SimulateRigFolder(const RigSimOptions& options, const std::filesystem::path& out_dir);

}  // namespace calibench
