// The targetless check measured on simulated textured rooms (docs/targetless.md "Simulation"):
// for each seed a room, a rig (still, or moving through the room) and a LiDAR (spinning or
// Livox-class) give frames; the check then judges the true extrinsic (a false alarm if it says
// miscalibrated) and the truth moved by each error size in a random direction (caught if it
// says miscalibrated), and the estimate's error is compared with its σ (χ², 6 axes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/camera/camera.h"
#include "core/lidar/cloud.h"
#include "core/targetless/check.h"

namespace calibench {

struct CheckSweepOptions {
  // "vlp16", "os0-128", "hdl64" (spinning) or "mid40", "avia", "mid360" (Livox-class).
  std::string lidar = "vlp16";
  bool moving = false;  // the rig drives through the room (one pose per frame) or stands still
  int seeds = 6;
  std::uint64_t first_seed = 1;
  int frames = 8;               // per seed
  double range_noise_m = 0.01;  // along each ray
  double image_noise = 0.01;    // [0,1] intensity units
  double livox_hold_s = 1.0;    // a Livox-class frame: returns of this long at one pose
  std::vector<double> rotation_errors_deg = {0.25, 0.5, 1.0};
  std::vector<double> translation_errors_m = {0.01, 0.02, 0.05};
  CheckOptions check;
  int threads = 0;  // 0 = DefaultThreads()
  bool Check(std::string* why) const;
};

// The frames of one seed and the truth they were made with.
struct SimulatedCheckFrame {
  std::string id;
  LidarCloud cloud;
  ImageU8 image;
};
struct SimulatedCheckScene {
  CameraModel camera;
  Pose cam_from_lidar = Pose::Identity();  // the truth
  std::vector<SimulatedCheckFrame> frames;
};
// The sweep's camera: 1280x960 pinhole rad-tan, fx 900 px.
CameraModel CheckSweepCamera();
SimulatedCheckScene SimulateCheckScene(const CheckSweepOptions& options, std::uint64_t seed);
// The scene as a dataset folder (clouds/, images/, camera.yaml) and truth.result.json beside it,
// for `calibench check` and the views.
void WriteCheckScene(const SimulatedCheckScene& scene, const std::filesystem::path& dir);

// One error size (or none) over all seeds.
struct CheckSweepRow {
  std::string error;  // "none", "0.5 deg", "2 cm"
  int trials = 0;
  int miscalibrated = 0;  // the verdict (caught; a false alarm on "none")
  int consistent = 0;
  int cannot_tell = 0;
  int significant = 0;  // the change from R beyond 3σ, whether or not above the tolerance
  int with_estimate = 0;
  int covered = 0;         // the estimate's error χ² (6 axes) below the 95 % level (12.59)
  double mean_chi2 = 0.0;  // over trials with an estimate; 6 when σ is honest
  double median_error_deg = 0.0, median_error_mm = 0.0;  // the estimate from the truth
};
struct CheckSweepResult {
  CheckSweepOptions options;
  std::vector<CheckSweepRow> rows;
  double seconds_per_check = 0.0;
};
using CheckSweepProgress = std::function<void(int seed_done, int seeds)>;
CheckSweepResult RunCheckSweep(const CheckSweepOptions& options,
                               const CheckSweepProgress& progress = {});

std::string FormatCheckSweep(const CheckSweepResult& result);
std::string CheckSweepJson(const CheckSweepResult& result);

}  // namespace calibench
