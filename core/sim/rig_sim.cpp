#include "core/sim/rig_sim.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/io/camera_file.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"

namespace calibench {

bool RigSimOptions::Check(std::string* why) const {
  if (!base.Check(why)) return false;
  if (num_captures < 3) return *why = "num_captures must be >= 3", false;
  if (!(std::abs(second_camera_yaw_deg) <= 120.0))
    return *why = "second_camera_yaw_deg must lie in [-120, 120]", false;
  return true;
}

RigSimTruth SimulateRigFolder(const RigSimOptions& options, const std::filesystem::path& out_dir) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument(why);
  SimOptions resolved[2];
  resolved[0] = ResolveSimOptions(options.base);
  resolved[1] = resolved[0];
  resolved[1].camera =
      options.second_camera.width > 0 ? options.second_camera : DefaultSimCamera(/*fisheye=*/true);
  // Camera 1: camera 0's mount turned about the LiDAR's z axis and moved 20 cm to the left.
  Pose lidar_from_cam1 = resolved[0].cam_from_lidar.inverse();
  lidar_from_cam1.linear() =
      Eigen::AngleAxisd(options.second_camera_yaw_deg * kDegToRad, Vec3::UnitZ())
          .toRotationMatrix() *
      lidar_from_cam1.linear();
  lidar_from_cam1.translation() += Vec3(0.0, 0.20, 0.0);
  resolved[1].cam_from_lidar = lidar_from_cam1.inverse();
  RigSimTruth truth;
  truth.cam_from_lidar = {resolved[0].cam_from_lidar, resolved[1].cam_from_lidar};

  namespace fs = std::filesystem;
  fs::create_directories(out_dir / "clouds");
  fs::create_directories(out_dir / "cameras");
  for (const char* name : {"cam0", "cam1"}) fs::create_directories(out_dir / "images" / name);
  for (int c = 0; c < 2; ++c)
    SaveCameraFile(out_dir / "cameras" / ("cam" + std::to_string(c) + ".yaml"), resolved[c].camera,
                   CameraFileFormat::kRosCameraInfo, "cam" + std::to_string(c));
  SaveTargetFile(out_dir / "target.json", resolved[0].board);
  for (int k = 0; k < options.num_captures; ++k) {
    // The board is placed for one camera in turn (camera 1 every third capture) ...
    const int placed_for = k % 3 == 2 ? 1 : 0;
    const Pose cam_from_board = RandomPlacement(resolved[placed_for], k);
    const SimulatedPair pair = SimulatePairAt(resolved[placed_for], cam_from_board, k);
    char stem[16];
    std::snprintf(stem, sizeof(stem), "%04d", k);
    SavePcd(out_dir / "clouds" / (std::string(stem) + ".pcd"), pair.cloud);
    SaveImage(
        out_dir / "images" / ("cam" + std::to_string(placed_for)) / (std::string(stem) + ".png"),
        pair.image);
    // ... and the other camera writes its frame when it sees the whole sheet.
    const int other = 1 - placed_for;
    const Pose other_from_board = resolved[other].cam_from_lidar *
                                  resolved[placed_for].cam_from_lidar.inverse() * cam_from_board;
    if (!PlaceableInSimulation(resolved[other], other_from_board)) continue;
    RenderOptions render;
    render.image_noise = resolved[other].image_noise;
    render.seed = resolved[other].seed * 1000003ULL + static_cast<std::uint64_t>(k);
    SaveImage(
        out_dir / "images" / ("cam" + std::to_string(other)) / (std::string(stem) + ".png"),
        RenderBoardImage(resolved[other].camera, resolved[other].board, other_from_board, render));
    ++truth.shared_captures;
  }
  return truth;
}

}  // namespace calibench
