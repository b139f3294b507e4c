// The calibench.lrf-dataset.v1 manifest (docs/architecture.md, "Conventions and file contracts")
// and its files: LaserScan-like JSON scans, plain 2D PCD scans (z = 0), 16-bit depth PNGs and
// depth-frame PCDs.
//
// Beyond the agreed contract, the same manifest carries the LRF ↔ RGB camera checkerboard case
// (Zhang & Pless): "target": {"type": "checkerboard", ...} as in calibench.dataset.v1, "camera" (or
// "camera_file") for the RGB intrinsics, and "image" per pair instead of "depth"/"cloud".
// Optional fields: per pair "scan_region" {"angle_min_deg", "angle_max_deg", "range_min",
// "range_max"} (the file form of the user's selection on the scan plot); top level
// "initial_guess": {"cam_from_lrf": 4x4} and "stereo": {"right_from_left": 4x4} (the right
// depth camera's pose from the left one, for `evaluate --stereo`).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/io/dataset.h"
#include "core/io/load_limits.h"
#include "core/lrf_data/types.h"

namespace calibench {

enum class LrfTargetType { kThreeFace, kCheckerboard };

// A user's selection of the target on the scan: an angular window and a range band.
struct ScanRegion {
  double angle_min = -M_PI;  // rad
  double angle_max = M_PI;   // rad
  double range_min = 0.0;    // m
  double range_max = 1e9;    // m
  bool Contains(double angle, double range) const {
    return angle >= angle_min && angle <= angle_max && range >= range_min && range <= range_max;
  }
};

struct LrfPairEntry {
  std::string id;
  std::filesystem::path scan;         // .json (LaserScan) or .pcd (2D, z = 0); absolute
  std::filesystem::path depth;        // 16-bit PNG (three-face), or empty
  std::filesystem::path depth_cloud;  // PCD in the depth-camera frame (three-face), or empty
  std::filesystem::path image;        // RGB image (checkerboard), or empty
  std::optional<ScanRegion> scan_region;
};

struct LrfDataset {
  std::filesystem::path manifest;
  LrfTargetType target_type = LrfTargetType::kThreeFace;
  ThreeFaceTarget three_face;    // kThreeFace
  DepthIntrinsics depth_camera;  // kThreeFace
  CameraModel camera;            // kCheckerboard
  BoardSpec board;               // kCheckerboard
  std::vector<LrfPairEntry> pairs;
  std::optional<Pose> cam_from_lrf_ground_truth;
  std::optional<Pose> initial_cam_from_lrf;
  std::optional<Pose> right_from_left;  // stereo: right camera from left camera
};

// `path` is the manifest, whatever its name, or a folder holding it (ResolveDataset). Throws
// IoError naming the file and the problem (not an LRF dataset, missing fields, wrong format
// string, missing files, bad target or intrinsics).
LrfDataset LoadLrfDataset(const std::filesystem::path& path);
// Writes atomically; paths relative to the manifest's folder when they lie under it.
void SaveLrfDataset(const std::filesystem::path& manifest_path, const LrfDataset& dataset);

// A scan from a LaserScan JSON (null / "inf" / "nan" = no return) or a 2D PCD (x y [z] …;
// points at the origin are no returns; the points are binned by angle into an evenly spaced
// scan whose increment is the median angular spacing). Throws IoError naming the file.
LaserScan LoadLaserScan(const std::filesystem::path& path, const LoadLimits& limits = {});
void SaveLaserScanJson(const std::filesystem::path& path, const LaserScan& scan);

// A 16-bit single-channel PNG scaled by intrinsics.depth_scale (0 = no data). Throws IoError
// naming the file when it is not 16-bit single-channel or its size differs from the intrinsics
// (both read from the PNG header before decoding), or has more than limits.max_depth_pixels.
DepthImage LoadDepthPng(const std::filesystem::path& path, const DepthIntrinsics& intrinsics,
                        const LoadLimits& limits = {});
// Writes a 16-bit PNG (depth / depth_scale, rounded; values beyond 65535 units become 0).
void SaveDepthPng(const std::filesystem::path& path, const DepthImage& depth);
// A PCD in the depth-camera frame, projected by the intrinsics into a depth image (nearest z
// wins). Throws IoError naming the file.
DepthImage LoadDepthCloud(const std::filesystem::path& path, const DepthIntrinsics& intrinsics,
                          const LoadLimits& limits = {});

// The depth of a pair (PNG or cloud, whichever the entry names).
DepthImage LoadPairDepth(const LrfDataset& dataset, const LrfPairEntry& pair);

}  // namespace calibench
