// The calibench.dataset.v1 manifest (DESIGN.md "File contracts"), its folder shorthand, and
// camera intrinsics files (inline JSON, OpenCV FileStorage YAML, ROS camera_info YAML, Kalibr).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/types.h"

namespace calibench {

enum class BoardType { kCheckerboard, kCharuco };

// A printed target. Board frame: origin at the pattern centre, x along columns, y along rows,
// z = x × y pointing out of the back of the board (away from a camera that sees the print).
struct BoardSpec {
  BoardType type = BoardType::kCheckerboard;
  // checkerboard: inner corners [cols, rows]; charuco: squares [cols, rows].
  int cols = 0;
  int rows = 0;
  double square_size = 0.0;  // metres
  double marker_size = 0.0;  // metres, charuco only
  std::string dictionary;    // charuco only, e.g. "DICT_4X4_50"
  // Physical sheet [width, height] in metres, pattern centred on it; 0 = unknown.
  double board_width = 0.0;
  double board_height = 0.0;

  bool Check(std::string* why) const;
  // Number of squares along x and y.
  int SquaresX() const { return type == BoardType::kCheckerboard ? cols + 1 : cols; }
  int SquaresY() const { return type == BoardType::kCheckerboard ? rows + 1 : rows; }
  // Pattern extent (metres).
  double PatternWidth() const { return SquaresX() * square_size; }
  double PatternHeight() const { return SquaresY() * square_size; }
  // Sheet size if known, else the pattern size.
  double SheetWidth() const { return board_width > 0 ? board_width : PatternWidth(); }
  double SheetHeight() const { return board_height > 0 ? board_height : PatternHeight(); }
};

// The file form of the user's brush: a point in the LiDAR frame near the board centre.
struct LidarSeed {
  Vec3 point = Vec3::Zero();  // metres, LiDAR frame
  double radius = 0.0;        // metres
};

struct PairEntry {
  std::string id;
  std::filesystem::path cloud;  // absolute after loading
  std::filesystem::path image;  // absolute after loading
  std::optional<LidarSeed> lidar_seed;
};

// What `calibench simulate` was asked for, so that every pair's noise-free geometry can be
// re-created (SimOptionsFromDataset in sim.h) for the Cramér–Rao bound. Camera, board and ground
// truth are the dataset's own.
struct SimulationRecord {
  std::string lidar_model;  // "hdl64", "vlp16", "os0-128"
  int num_pairs = 0;
  double min_distance_m = 0.0;
  double max_distance_m = 0.0;
  double max_tilt_deg = 0.0;
  double lidar_range_noise_m = 0.0;   // 1σ along each ray
  double lidar_range_offset_m = 0.0;  // measured = true range + offset
  double image_noise = 0.0;           // [0,1] intensity units
  bool clutter = true;
  double seed_radius_m = 0.0;
  std::uint64_t seed = 1;
};

struct Dataset {
  std::filesystem::path manifest;  // the file read (or the folder for the shorthand)
  CameraModel camera;
  BoardSpec target;
  int lidar_rings = 0;  // 0 = unknown
  std::vector<PairEntry> pairs;
  std::optional<Pose> cam_from_lidar_ground_truth;
  std::optional<SimulationRecord> simulation;
};

// Loads a manifest file, or a folder with clouds/ + images/ (paired by stem), camera.yaml and
// target.json. Relative paths resolve against the manifest's folder. Throws IoError naming the
// file and the problem; validates the camera and the target.
Dataset LoadDataset(const std::filesystem::path& path);

// Writes a manifest; paths are written relative to the manifest's folder when they lie under it.
void SaveDataset(const std::filesystem::path& manifest_path, const Dataset& dataset);

// Reads intrinsics from an OpenCV FileStorage YAML/XML (camera_matrix, distortion_coefficients,
// optional distortion_model), a ROS camera_info YAML (camera_calibration output or the CameraInfo
// message fields K/D), or a Kalibr camchain (cam0). The model must be stated by the file
// (plumb_bob / rational_polynomial / radtan -> pinhole-radtan; equidistant / fisheye ->
// kannala-brandt); OpenCV FileStorage files without a model are pinhole-radtan by definition.
CameraModel LoadCameraFile(const std::filesystem::path& path);

}  // namespace calibench
