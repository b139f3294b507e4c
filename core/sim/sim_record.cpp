// A simulated dataset's options read back from its manifest's simulation record (sim.h).
#include <string>

#include "core/sim/sim.h"

namespace calibench {

SimOptions SimOptionsFromDataset(const Dataset& dataset) {
  if (!dataset.simulation)
    throw IoError(dataset.manifest.string() +
                  ": no \"simulation\" record (only datasets written by `calibench simulate` "
                  "carry the noise settings the bound needs)");
  const SimulationRecord& record = *dataset.simulation;
  SimOptions options;
  const auto lidar = ParseLidarModelName(record.lidar_model);
  if (!lidar)
    throw IoError(dataset.manifest.string() + ": simulation.lidar_model '" + record.lidar_model +
                  "' is not one of " + LidarModelNames());
  options.lidar = *lidar;
  options.camera = dataset.camera;
  options.board = dataset.target;
  options.num_pairs = record.num_pairs;
  options.min_distance_m = record.min_distance_m;
  options.max_distance_m = record.max_distance_m;
  options.max_tilt_deg = record.max_tilt_deg;
  if (record.lidar_frame_s > 0) options.lidar_frame_s = record.lidar_frame_s;
  options.lidar_range_noise_m = record.lidar_range_noise_m;
  options.lidar_range_offset_m = record.lidar_range_offset_m;
  options.lidar_angular_noise_rad = record.lidar_angular_noise_rad;
  options.lidar_viewpoints = record.lidar_viewpoints;
  options.image_noise = record.image_noise;
  options.clutter = record.clutter;
  options.board_only_clouds = record.board_only_clouds;
  options.seed_radius_m = record.seed_radius_m;
  options.seed = record.seed;
  if (dataset.cam_from_lidar_ground_truth)
    options.cam_from_lidar = *dataset.cam_from_lidar_ground_truth;
  std::string why;
  if (!options.Check(&why))
    throw IoError(dataset.manifest.string() + ": simulation record: " + why);
  return options;
}

}  // namespace calibench
