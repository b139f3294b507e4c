#include "tests/acfr_manifest.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"

namespace calibench::test {

Pose AcfrReferenceCamFromLidar() {
  // README: R = Rz(yaw) Ry(pitch) Rx(roll), p_lidar = R p_cam + t (lidar_from_cam), mean of 50.
  const double roll = -1.69539, pitch = -0.02093, yaw = -1.49289;
  Pose lidar_from_cam = Pose::Identity();
  lidar_from_cam.linear() =
      (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
       Eigen::AngleAxisd(roll, Vec3::UnitX()))
          .toRotationMatrix();
  lidar_from_cam.translation() = Vec3(0.06263, 0.00389, -0.19583);
  return lidar_from_cam.inverse();
}

std::filesystem::path WriteAcfrManifest(const std::filesystem::path& dataset_dir,
                                        const std::filesystem::path& out_dir,
                                        double seed_radius_m) {
  const std::filesystem::path csv = dataset_dir / "poses.csv";
  std::ifstream in(csv);
  if (!in) throw IoError(csv.string() + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::vector<double> values;
    std::string item;
    while (std::getline(ss, item, ',')) values.push_back(std::stod(item));
    if (values.size() != 3) throw IoError(csv.string() + ": a row without 3 values");
    rows.push_back(values);
  }
  constexpr int kRowsPerSample = 19;
  if (rows.empty() || rows.size() % kRowsPerSample != 0)
    throw IoError(csv.string() + ": expected blocks of 19 rows, got " +
                  std::to_string(rows.size()));

  Dataset dataset;
  dataset.camera = LoadCameraFile(dataset_dir / "camera_info.yaml");
  dataset.target.type = BoardType::kCheckerboard;
  dataset.target.cols = 5;  // 5 inner corners along the 610 mm side, 7 along the 850 mm side
  dataset.target.rows = 7;
  dataset.target.square_size = 0.095;
  dataset.target.board_width = 0.61;
  dataset.target.board_height = 0.85;
  dataset.lidar_rings = 16;
  for (size_t block = 0; block < rows.size() / kRowsPerSample; ++block) {
    const auto& centre_mm = rows[block * kRowsPerSample + 6];  // row 7: LiDAR-frame board centre
    const int n = static_cast<int>(std::lround(rows[block * kRowsPerSample + 18][0]));
    PairEntry pair;
    pair.id = "pose" + std::to_string(n);
    pair.cloud = dataset_dir / "pcd" / ("pose" + std::to_string(n) + "_full.pcd");
    pair.image = dataset_dir / "images" / ("pose" + std::to_string(n) + ".png");
    pair.lidar_seed =
        LidarSeed{Vec3(centre_mm[0], centre_mm[1], centre_mm[2]) / 1000.0, seed_radius_m};
    dataset.pairs.push_back(pair);
  }
  dataset.cam_from_lidar_ground_truth = AcfrReferenceCamFromLidar();
  std::filesystem::create_directories(out_dir);
  const std::filesystem::path manifest = out_dir / "dataset.json";
  SaveDataset(manifest, dataset);
  return manifest;
}

std::filesystem::path WriteAcfrFolder(const std::filesystem::path& acfr,
                                      const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::remove_all(dir);
  fs::create_directories(dir / "clouds");
  fs::create_directories(dir / "images");
  for (int n = 1; n <= 40; ++n) {
    const std::string id = "pose" + std::to_string(n);
    fs::create_symlink(acfr / "pcd" / (id + "_full.pcd"), dir / "clouds" / (id + ".pcd"));
    fs::create_symlink(acfr / "images" / (id + ".png"), dir / "images" / (id + ".png"));
  }
  fs::create_symlink(acfr / "camera_info.yaml", dir / "camera.yaml");
  std::ofstream(dir / "target.json") << R"({"type": "checkerboard", "inner_corners": [5, 7],
    "square_size": 0.095, "board_size": [0.61, 0.85]})";
  return dir;
}

}  // namespace calibench::test
