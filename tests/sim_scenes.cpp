#include "tests/sim_scenes.h"

#include <cmath>

#include "core/io/cloud_io.h"
#include "core/sim/sim.h"

namespace calibench::test {

std::map<std::string, Plane> TrueBoardPlanes(const Dataset& dataset) {
  const std::vector<Pose> cam_from_board = SampleBoardPoses(SimOptionsFromDataset(dataset));
  const Pose lidar_from_cam = dataset.cam_from_lidar_ground_truth->inverse();
  std::map<std::string, Plane> planes;
  for (size_t i = 0; i < dataset.pairs.size(); ++i) {
    const Pose lidar_from_board = lidar_from_cam * cam_from_board.at(i);
    Vec3 normal = lidar_from_board.linear().col(2);
    if (normal.dot(lidar_from_board.translation()) > 0) normal = -normal;
    planes[dataset.pairs[i].id] = Plane{normal, -normal.dot(lidar_from_board.translation())};
  }
  return planes;
}

Dataset CompletionMattersScene(const std::filesystem::path& dir) {
  SimOptions sim = SimPreset("default");
  sim.lidar = LidarModel::kOs0_128;
  sim.num_pairs = 10;
  sim.lidar_range_noise_m = 0.005;
  sim.seed = 23;
  Dataset dataset = SimulateDataset(sim, dir);
  for (PairEntry& pair : dataset.pairs) pair.lidar_seed.reset();
  SaveDataset(dataset.manifest, dataset);
  const auto truth = TrueBoardPlanes(dataset);
  // The decoy: a sheet of the board's size facing the LiDAR, away from the board (opposite
  // azimuth), cast with the same beams and appended to pair 3's cloud.
  const PairEntry& victim = dataset.pairs[3];
  LidarCloud cloud = LoadCloud(victim.cloud);
  const Vec3 board_dir = -truth.at(victim.id).normal;
  const double azimuth = std::atan2(board_dir.y(), board_dir.x()) + M_PI / 2;
  ScenePanel decoy;
  const Vec3 centre(2.2 * std::cos(azimuth), 2.2 * std::sin(azimuth), 0.0);
  const Vec3 z = Vec3(centre.x(), centre.y(), 0).normalized(), y = -Vec3::UnitZ();
  decoy.lidar_from_panel.linear() << y.cross(z), y, z;
  decoy.lidar_from_panel.translation() = centre;
  decoy.size_m = Vec2(dataset.target.SheetWidth(), dataset.target.SheetHeight());
  LidarScene scene;
  scene.clutter = false;
  scene.lidar_from_board.translation() = Vec3(0, 0, 500);  // the print itself: out of reach
  scene.panels.push_back(decoy);
  LidarScanOptions scan_options;
  scan_options.range_noise_m = 0.005;
  const LidarCloud extra =
      SimulateLidarScan(MakeBeamTable(sim.lidar), BoardPrint(dataset.target), scene, scan_options)
          .ToCloud();
  cloud.points.insert(cloud.points.end(), extra.points.begin(), extra.points.end());
  cloud.intensity.insert(cloud.intensity.end(), extra.intensity.begin(), extra.intensity.end());
  cloud.ring.insert(cloud.ring.end(), extra.ring.begin(), extra.ring.end());
  cloud.width = static_cast<int>(cloud.size());
  SavePcd(victim.cloud, cloud);
  return dataset;
}

}  // namespace calibench::test
