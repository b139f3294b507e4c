// Simulator for the 2D LRF ↔ depth camera method: a 2D LRF (field of view, angular step, range
// noise), a pinhole depth camera whose depth noise grows with z² (stereo: σ_z = z² σ_disp/(f b)),
// the three-face target (lrf_types.h) at poses that keep the scan on all three faces, walls as
// clutter, and an optional right depth camera at a known baseline (the paper's Section 4.3
// evaluation). Deterministic for a seed; writes real files (calibench.lrf-dataset.v1).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/lrf_data/dataset.h"
#include "core/lrf_data/types.h"

namespace calibench {

struct LrfSensorSpec {
  double fov_deg = 360.0;           // centred on +x
  double angular_step_deg = 0.042;  // R2000
  double range_noise_m = 0.0125;    // 1σ; the R2000's ±25 mm taken as 2σ
  double range_min_m = 0.1;
  double range_max_m = 30.0;
  bool Check(std::string* why) const;
};

struct DepthCameraSpec {
  DepthIntrinsics intrinsics{1280, 720, 700.0, 700.0, 640.0, 360.0, 0.001};  // ZED-like HD720
  double stereo_baseline_m = 0.12;   // of the depth camera's own stereo pair (noise model)
  double disparity_noise_px = 0.15;  // 1σ; σ_z = z² σ_disp / (f b)
  double max_depth_m = 10.0;         // beyond: no data
  bool Check(std::string* why) const;
};

// The LRF mounted 0.15 m above and 0.10 m behind the camera, level to within a few degrees, x
// forward (paper Fig. 5b): cam_from_lrf maps LRF x (forward) to camera z, LRF y (left) to -x,
// LRF z (up) to -y, then a small tilt.
Pose DefaultCamFromLrf();

struct LrfSimOptions {
  int observations = 20;
  uint64_t seed = 1;
  LrfSensorSpec lrf;
  DepthCameraSpec depth;
  ThreeFaceTarget target;
  Pose cam_from_lrf = DefaultCamFromLrf();
  double target_distance_min_m = 1.0;  // from the camera
  double target_distance_max_m = 3.0;
  double target_max_yaw_deg = 30.0;       // about the target's y (up) axis
  double target_max_tilt_deg = 10.0;      // about the target's x axis
  bool clutter = true;                    // back wall, side wall and floor
  bool stereo = false;                    // also a right depth camera
  double stereo_right_baseline_m = 0.12;  // right camera at +x of the left one
  bool Check(std::string* why) const;
};

// "paper" (R2000 + ZED-like, the default) or "ideal" (noise-free). nullopt for other names.
std::optional<LrfSimOptions> LrfSimPreset(const std::string& name);

// One rendered observation, in memory.
struct LrfSimObservation {
  Pose cam_from_target = Pose::Identity();
  LaserScan scan;
  DepthImage depth;        // left (or only) camera
  DepthImage depth_right;  // stereo only
};

// Target poses (camera frame) valid for the options: the scan plane crosses AB, AC and AD within
// the faces, all three faces are seen by the camera with enough pixels. Deterministic for the seed.
std::vector<Pose> SampleTargetPoses(const LrfSimOptions& options);

// Renders one observation (ray casting for the scan and per depth pixel, then noise).
LrfSimObservation RenderLrfObservation(const LrfSimOptions& options, const Pose& cam_from_target,
                                       uint64_t noise_seed);

// Writes out_dir/manifest.json (+ out_dir/right.json when stereo), scans/NNNN.json,
// depth/NNNN.png (+ depth_right/NNNN.png), with ground truth. Returns the left manifest path.
// Throws IoError when out_dir cannot be written.
std::filesystem::path WriteLrfSimDataset(const LrfSimOptions& options,
                                         const std::filesystem::path& out_dir);

}  // namespace calibench
