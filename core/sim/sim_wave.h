// A board waved in front of the rig, never still (docs/architecture.md "Time"): a spinning
// LiDAR's sweeps (or a Risley pattern's frames, the rosette going on from frame to frame), each
// return at its own time with the board where it was then, and a camera
// whose stamps are off the LiDAR's clock by a set offset. Written as a moving capture's dataset:
// each sweep that sees the board a pair with its `lidar_stamp_ns`, its cloud's field `t`, and
// every camera frame within a window of its stamp (the manifest's "images").
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/io/dataset.h"
#include "core/sim/sim.h"

namespace calibench {

struct WaveOptions {
  // The rig, the board and the noise (lidar: a spinning model or a Risley pattern, a frame per
  // 1 / lidar_hz; its pairs are the wave's sweeps).
  SimOptions rig;
  double duration_s = 40.0;
  // The board's centre runs an ellipse in front of the camera at this speed (m/s), with a slow
  // bob up and down, turning up to max_tilt_deg about the camera's x and y axes as it goes.
  double speed_mps = 0.45;
  double centre_distance_m = 2.0;  // the ellipse's centre, along the camera's z
  double across_m = 0.6;           // half its width (camera x)
  double depth_m = 0.5;            // half its depth (camera z)
  double max_tilt_deg = 25.0;
  double lidar_hz = 10.0;
  double camera_hz = 10.0;
  // The camera's stamp of an instant minus the LiDAR clock's time of it (seconds): +0.040 means
  // the camera's stamps are 40 ms late.
  double camera_minus_lidar_s = 0.040;
  // A pair keeps every frame stamped within this of its sweep (seconds, either side), and one
  // frame beyond: the offset's search window (TimeOffsetOptions::search_s) is then covered.
  double images_window_s = 0.25;
  // A sweep is a pair when this many of its returns lie on the sheet.
  int min_board_returns = 60;
  // Every sweep's cloud written, those without the board too (for a recording of the stream,
  // tests/sim_recording.h); else only the pairs'.
  bool every_sweep = false;

  bool Check(std::string* why) const;
};

// The board's pose at true time `t` (seconds after the recording starts; camera frame).
Pose WavedCamFromBoard(const WaveOptions& options, double t);

struct WavedDataset {
  Dataset dataset;  // as written (dataset.json under the folder)
  // Per pair, as dataset.pairs: the board at its returns' median time and its noise-free returns
  // there (for the Cramér–Rao bound of the same sweeps, core/evaluation/crlb.h).
  std::vector<SimPairTruth> truth;
  int sweeps = 0;  // LiDAR sweeps simulated
  int frames = 0;  // camera frames rendered
  // Every frame rendered (images/frame_<k>.png, stamped on the camera's clock) and every sweep
  // written (clouds/sweep_<j>.pcd, stamped at its start on the LiDAR's), in time order.
  std::vector<StampedImage> frame_files;
  std::vector<std::pair<std::filesystem::path, std::int64_t>> sweep_files;
  double median_speed_mps = 0.0;  // the board's centre, over the recording
};

// Writes the folder (clouds/, images/, camera.yaml-free manifest with the camera inline) and
// returns what it wrote. Throws std::invalid_argument for bad options.
WavedDataset SimulateWavedDataset(const WaveOptions& options, const std::filesystem::path& out_dir);

}  // namespace calibench
