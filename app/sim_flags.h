// Simulation flags shared by `simulate`, `demo` and `sweep`.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "core/sim/sim.h"

namespace calibench::app {

struct SimFlags {
  std::string preset = "default";
  std::string lidar, camera, board;
  std::string image_size;   // "WxH": the preset's camera scaled to it; empty = 1440x1080
  int pairs = 0;            // 0 = the preset's
  double lidar_noise = -1;  // < 0 = the preset's
  double lidar_range_offset = 0;
  double lidar_angular_noise_deg = 0;
  double lidar_frame = 0;   // 0 = the model's frame (0.1 s)
  double image_noise = -1;  // < 0 = the preset's
  double min_distance = 0;  // 0 = the preset's
  double max_distance = 0;  // 0 = the preset's
  std::uint64_t seed = 1;
  bool no_clutter = false;
  bool board_only_clouds = false;
  bool lidar_viewpoints = false;
  bool no_lidar_seeds = false;
};

void AddSimFlags(CLI::App& app, SimFlags& flags);
// Preset + overrides; false with *why for unknown names or options failing Check.
bool BuildSimOptions(const SimFlags& flags, SimOptions* options, std::string* why);

}  // namespace calibench::app
