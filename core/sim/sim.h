// Synthetic LiDAR + camera scenes with ground truth, written as real dataset files
// (PCD clouds, PNG images, a calibench.dataset.v1 manifest). Deterministic for a seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/io/dataset.h"
#include "core/lidar/beam_table.h"
#include "core/lidar/cloud.h"
#include "core/target/board_print.h"

namespace calibench {

struct SimOptions {
  LidarModel lidar = LidarModel::kVlp16;
  CameraModel camera;    // empty width = a default 1440x1080 pinhole-radtan (or fisheye)
  bool fisheye = false;  // used only when `camera` is empty
  BoardSpec board;       // cols == 0 = A3 checkerboard (7x5 inner corners, 40 mm squares)
  int num_pairs = 20;
  double min_distance_m = 1.5;  // board centre distance from the camera
  double max_distance_m = 4.0;
  double max_tilt_deg = 40.0;            // board normal vs. the camera viewing ray
  double lidar_range_noise_m = 0.0;      // Gaussian, along each ray
  double lidar_angular_noise_rad = 0.0;  // Gaussian, across each ray (LidarScanOptions)
  // A Livox-class LiDAR (mid40, avia, mid360): the seconds of returns each pair's cloud holds —
  // one 0.1 s frame, or a still hold integrated (1 s: ten times the points).
  double lidar_frame_s = 0.1;
  // Constant error of the LiDAR's range calibration: measured range = true range + offset (m).
  double lidar_range_offset_m = 0.0;
  double image_noise = 0.0;  // Gaussian pixel noise, in [0,1] intensity units (Gazebo)
  bool clutter = true;       // floor and walls
  // Clouds cropped to the returns on the sheet, without rings, as several public sets and some
  // users' pipelines ship the LiDAR side: no background, nothing beyond the board's edges.
  bool board_only_clouds = false;
  // Each return's ray origin in its cloud (the fields vp_x, vp_y, vp_z, core/lidar/cloud.h), as a
  // swept scanner's driver that knows its mirror can write them.
  bool lidar_viewpoints = false;
  Pose cam_from_lidar = Pose::Identity();  // ground truth; Identity() = the default mount below
  double seed_radius_m = 0.0;              // lidar_seed radius; 0 = 0.4 * the smaller board side
  // Whether each pair carries a lidar_seed (where its board is, as a seeding tool would say). Off:
  // a user's dataset, the board to be found in the cloud by itself.
  bool lidar_seeds = true;
  std::uint64_t seed = 1;

  bool Check(std::string* why) const;
};

// The simulator's cameras, 1440x1080: pinhole rad-tan (fx = 1000 px) or Kannala-Brandt fisheye
// (fx = 450 px).
CameraModel DefaultSimCamera(bool fisheye);

// The default mount: LiDAR x forward, z up; camera z forward, y down; camera 10 cm below and
// 5 cm left of the LiDAR with a small rotation, so that the solver cannot get lucky with axes.
Pose DefaultCamFromLidar();

// Presets: "default" (VLP-16, pinhole, A3 checkerboard), "paper" (Ca²Lib Section 4.1:
// HDL-64, 6x8-square checkerboard with 0.2 m squares, 1440x1080 camera), "demo" (OS0-128,
// A3 checkerboard, 16 pairs at 1.2-3 m).
// Throws std::invalid_argument naming the known presets for any other name.
SimOptions SimPreset(const std::string& name);

// What a simulated sweep can hit, in the LiDAR frame: one board and, with clutter, a floor and the
// four walls of a square room centred on the LiDAR (walls and floor unbounded).
// A flat rectangle in the scene that is not the board: a panel on a wall, a door, a second board.
// Its plane is its frame's xy plane, centred on the origin.
struct ScenePanel {
  Pose lidar_from_panel = Pose::Identity();
  Vec2 size_m = Vec2::Zero();  // [x, y] extent, metres
};

struct LidarScene {
  Pose lidar_from_board = Pose::Identity();
  // A board that moves during the sweep (a waved board): its pose at each return's time, seconds
  // after the sweep's start (LidarScanOptions::sweep_s); empty: lidar_from_board throughout.
  std::function<Pose(double seconds)> lidar_from_board_at;
  std::vector<ScenePanel> panels;  // hit as walls are (SimSurface::kWall)
  bool clutter = true;
  double floor_z_m = -1.5;       // floor plane z = floor_z_m (metres, LiDAR frame)
  double wall_distance_m = 6.0;  // walls at x = ±d and y = ±d (metres, LiDAR frame)
};

struct LidarScanOptions {
  double range_noise_m = 0.0;  // Gaussian, along each ray (metres)
  // Gaussian jitter of each beam's direction (radians, 1σ per axis across the ray): the return
  // comes from the jittered ray but is stored along the nominal one, as a sensor's encoder and
  // beam divergence give (docs/architecture.md, "Noise learned from the data").
  double angular_noise_rad = 0.0;
  double range_offset_m = 0.0;      // added to every range (metres)
  double azimuth_offset_rad = 0.0;  // azimuth of step 0 (the firing phase of this sweep)
  std::uint64_t seed = 1;           // range and intensity noise
  // The sweep's time (seconds; > 0): each return's time after the sweep's start, when its step
  // fired (BeamRays::FiredFraction: a spinning LiDAR's step / steps of it, a Risley pattern's rays
  // at their own times), kept (LidarScan::time_s). 0: the sweep is instantaneous.
  double sweep_s = 0.0;
};

enum class SimSurface : std::uint8_t { kBoard, kFloor, kWall };

// One sweep in double precision (the PCD file stores floats). Intensities: white paper ~200,
// black ink ~20, walls ~90, floor ~60 (0..255, with small Gaussian noise).
struct LidarScan {
  std::vector<Vec3> points;         // metres, LiDAR frame
  std::vector<float> intensity;     // 0..255
  std::vector<int> ring;            // 0 = lowest beam
  std::vector<SimSurface> surface;  // what each return hit
  std::vector<Vec3> origin;         // where each return's ray started (a swept scanner's mirror)
  std::vector<float> time_s;        // after the sweep's start (LidarScanOptions::sweep_s > 0)
  bool has_rings = true;            // false for a swept scanner: its cloud has no ring field

  size_t size() const { return points.size(); }
  // Unorganized cloud (height 1) with intensity and ring (when it has rings); board_only: the
  // sheet's returns alone, without rings (SimOptions::board_only_clouds); viewpoints: each
  // return's ray origin (SimOptions::lidar_viewpoints); each return's time when the scan has them.
  LidarCloud ToCloud(bool board_only = false, bool viewpoints = false) const;
};

// Casts every beam × azimuth step (firing order: azimuth outer, rings inner) and keeps the nearest
// hit among the board sheet, the panels and, with clutter, the floor and walls; rays without a hit
// within [0.3 m, max_range_m] give no point. Range noise moves each point along its ray.
LidarScan SimulateLidarScan(const BeamTable& beams, const BoardPrint& print,
                            const LidarScene& scene, const LidarScanOptions& options);

// The board poses SimulateDataset uses, pair by pair (camera frame, the print facing the camera).
// Throws std::runtime_error when a pair cannot be placed under the options' constraints.
std::vector<Pose> SampleBoardPoses(const SimOptions& options);

// Rendering of one board into a camera image (used by the simulator and by the camera-side
// bias tests). The print faces the camera: board frame as in BoardSpec (origin at the pattern
// centre, x along columns, y along rows, z away from the viewer). White sheet margin up to the
// sheet size, then a mid-grey background (no clutter). Anti-aliased by supersampling.
struct RenderOptions {
  int supersampling = 4;     // samples per pixel along each axis
  double image_noise = 0.0;  // Gaussian, [0,1] intensity units
  std::uint8_t background = 100;
  std::uint64_t seed = 1;
};
ImageU8 RenderBoardImage(const CameraModel& camera, const BoardSpec& board,
                         const Pose& cam_from_board, const RenderOptions& options);

// The options with every default filled in (camera, board with its sheet size, mount, seed
// radius), as the simulator uses them.
SimOptions ResolveSimOptions(const SimOptions& options);

// Each pair's noise-free geometry as SimulateDataset places it: the board pose and the board's
// returns without range noise (LiDAR frame, the board alone). For the Cramér–Rao bound.
struct SimPairTruth {
  Pose cam_from_board = Pose::Identity();
  std::vector<Vec3> lidar_board_points;
};
std::vector<SimPairTruth> SimulatePairTruth(const SimOptions& options);

// One pair simulated in memory at a given board pose (guided capture, core/guidance): the cloud
// with the room, the image, and the seed a user's brush would give. `pair_index` draws the
// noise and the firing phase as SimulateDataset's pair of that index would. Options as
// ResolveSimOptions returns them.
struct SimulatedPair {
  LidarCloud cloud;
  ImageU8 image;
  LidarSeed seed;
};
SimulatedPair SimulatePairAt(const SimOptions& resolved, const Pose& cam_from_board,
                             int pair_index);

// Whether the simulator itself would place a board there: the whole sheet in the image with a
// 5 % margin, in the room, inside the LiDAR's vertical field of view and hit by >= 4 rings and
// >= 60 points. *why (optional) names the first failed check.
bool PlaceableInSimulation(const SimOptions& resolved, const Pose& cam_from_board,
                           std::string* why = nullptr);

// Whether a board there would stand inside the simulated room (a hand cannot push it through a
// wall); unlike PlaceableInSimulation, nothing about what the sensors would see.
bool FitsInSimulatedRoom(const SimOptions& resolved, const Pose& cam_from_board);

// The board pose SimulateDataset's pair `pair_index` gets (random placement).
Pose RandomPlacement(const SimOptions& resolved, int pair_index);

// The simulator's options as recorded in a dataset it wrote (Dataset::simulation); throws
// IoError naming the manifest when the dataset carries no simulation record.
SimOptions SimOptionsFromDataset(const Dataset& dataset);

// Writes dataset.json, clouds/NNNN.pcd and images/NNNN.png under out_dir and returns the dataset
// as written (absolute paths, ground truth set). Throws IoError on write failures,
// std::invalid_argument for options that fail Check, std::runtime_error as SampleBoardPoses.
Dataset SimulateDataset(const SimOptions& options, const std::filesystem::path& out_dir);

}  // namespace calibench
