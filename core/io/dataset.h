// The calibench.dataset.v1 manifest (docs/architecture.md, "Conventions and file contracts") and
// its folder shorthand.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/base/types.h"
#include "core/board/board.h"
#include "core/camera/camera.h"

namespace calibench {

// One camera frame of a moving capture: the image and its stamp on the camera's clock.
struct StampedImage {
  std::filesystem::path image;  // absolute after loading
  std::int64_t stamp_ns = 0;
};

struct PairEntry {
  std::string id;
  std::filesystem::path cloud;  // absolute after loading
  // Absolute after loading. A moving capture's pair: the frame of `images` nearest its
  // lidar_stamp_ns (what a view of one image shows).
  std::filesystem::path image;
  std::optional<LidarSeed> lidar_seed;
  // The cloud's stamp on the LiDAR's clock (nanoseconds; the manifest's "lidar_stamp_ns", a
  // decimal string or an integer): what the cloud's per-point times (LidarCloud::time_s, a PCD /
  // PLY field `t`) count from. Absent: the pair is instantaneous.
  std::optional<std::int64_t> lidar_stamp_ns;
  // A moving capture (the manifest's "images" instead of "image", with lidar_stamp_ns): every
  // camera frame around the sweep, in stamp order (camera clock). Empty: one image, `image`.
  std::vector<StampedImage> images;
};

// What `calibench simulate` was asked for, so that every pair's noise-free geometry can be
// re-created (SimOptionsFromDataset in sim.h) for the Cramér–Rao bound. Camera, board and ground
// truth are the dataset's own.
struct SimulationRecord {
  std::string lidar_model;     // "hdl64", "vlp16", "os0-128", "swept-2d", "mid40", "avia", "mid360"
  double lidar_frame_s = 0.0;  // Livox-class: seconds of returns per cloud (0 = not recorded)
  int num_pairs = 0;
  double min_distance_m = 0.0;
  double max_distance_m = 0.0;
  double max_tilt_deg = 0.0;
  double lidar_range_noise_m = 0.0;      // 1σ along each ray
  double lidar_range_offset_m = 0.0;     // measured = true range + offset
  double lidar_angular_noise_rad = 0.0;  // 1σ per axis across each ray
  double image_noise = 0.0;              // [0,1] intensity units
  bool clutter = true;
  bool board_only_clouds = false;  // clouds cropped to the sheet's returns, without rings
  bool lidar_viewpoints = false;   // clouds carry each return's ray origin (vp_x, vp_y, vp_z)
  double seed_radius_m = 0.0;
  std::uint64_t seed = 1;
};

struct Dataset {
  std::filesystem::path manifest;  // the file read (or the folder for the shorthand)
  // One camera of a rig (core/io/rig_folder.h, LoadRigCamera): its name; `manifest` is then the
  // rig's folder or manifest. Empty for a single-camera dataset.
  std::string camera_name;
  CameraModel camera;
  BoardSpec target;
  int lidar_rings = 0;  // 0 = unknown
  std::vector<PairEntry> pairs;
  std::optional<Pose> cam_from_lidar_ground_truth;
  std::optional<SimulationRecord> simulation;
  // LoadDataset(path, CameraFile::kOptional) of a folder without camera.yaml: the file that is
  // missing (`camera` is then empty); empty when the camera was read.
  std::filesystem::path missing_camera_file;
  // LoadDataset(path, ..., TargetFile::kOptional) of a folder without target.json (a drive for
  // the targetless check: no board): the file that is missing; empty when the target was read.
  std::filesystem::path missing_target_file;
};

// Whether a folder dataset must bring its camera.yaml (`calibrate --estimate-intrinsics` and
// `intrinsics` read folders without one).
enum class CameraFile { kRequired, kOptional };
// Whether a folder dataset must bring its target.json: the targetless check (core/targetless)
// reads folders of scenes without a board; without one, Dataset::target keeps its default.
enum class TargetFile { kRequired, kOptional };

// Loads a manifest file, or a folder with clouds/ + images/ (paired by stem), camera.yaml and
// target.json. Relative paths resolve against the manifest's folder. Throws IoError naming the
// file and the problem; validates the camera and the target.
Dataset LoadDataset(const std::filesystem::path& path, CameraFile camera = CameraFile::kRequired,
                    TargetFile target = TargetFile::kRequired);

// The folder form's camera (camera.yaml) and target (target.json) without its pairs: a capture
// that has not written any yet (`calibench watch`). Throws IoError like LoadDataset.
Dataset LoadFolderSetup(const std::filesystem::path& dir, CameraFile camera = CameraFile::kRequired,
                        TargetFile target = TargetFile::kRequired);

// The board presets shipped as assets/targets/*.json, by name in name order; the built-in
// presets when that folder is missing (what the workbench's Board menu lists).
std::vector<std::pair<std::string, BoardSpec>> ShippedTargetPresets();

// A target file: the board spec at the top level or under "target" (target.json, a manifest).
// Throws IoError naming the file.
BoardSpec LoadTargetFile(const std::filesystem::path& path);
// Writes the board as a target file (target.json) atomically; throws IoError naming the file.
void SaveTargetFile(const std::filesystem::path& path, const BoardSpec& board);

// Writes a manifest; paths are written relative to the manifest's folder when they lie under it.
void SaveDataset(const std::filesystem::path& manifest_path, const Dataset& dataset);

}  // namespace calibench
