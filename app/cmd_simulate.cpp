#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "app/commands.h"
#include "app/sim_flags.h"
#include "core/sim/rig_sim.h"
#include "core/sim/sim.h"
#include "core/sim/sim_wave.h"

namespace calibench::app {

void AddSimFlags(CLI::App& app, SimFlags& flags) {
  app.add_option("--preset", flags.preset, "default | paper | demo")->capture_default_str();
  app.add_option(
      "--lidar", flags.lidar,
      "hdl64 | vlp16 | os0-128 | swept-2d (a 2D scanner on a rotary stage, its mirror off "
      "the axis; no rings) | nodding-2d (a line scanner tilted through ±20°: a 28° window) | mid40 "
      "| avia | mid360 (Livox-class non-repetitive scanners; no "
      "rings) (default: the preset's)");
  app.add_option("--lidar-frame", flags.lidar_frame,
                 "seconds of returns in each cloud of a Livox-class LiDAR: one frame (0.1) or a "
                 "still hold integrated (0.5-2) [s] (default: 0.1)");
  app.add_option("--camera", flags.camera, "pinhole | fisheye (default: the preset's)");
  app.add_option("--board", flags.board,
                 "a3 | a4 | paper | charuco-a3 | charuco-a4 (default: the preset's)");
  app.add_option("--image-size", flags.image_size,
                 "camera image WxH in pixels, the default camera's field of view kept "
                 "(default: 1440x1080)");
  app.add_option("--pairs", flags.pairs, "number of pairs (default: the preset's)");
  app.add_option("--lidar-noise", flags.lidar_noise, "LiDAR range noise sigma [m]");
  app.add_option("--lidar-range-offset", flags.lidar_range_offset,
                 "constant LiDAR range error [m]: measured range = true range + offset");
  app.add_option("--lidar-angular-noise-deg", flags.lidar_angular_noise_deg,
                 "jitter of each beam's direction [deg, 1 sigma per axis across the ray]: the "
                 "return comes from the jittered ray, stored along the nominal one");
  app.add_option("--image-noise", flags.image_noise, "image noise sigma in [0,1] intensity units");
  app.add_option("--min-distance", flags.min_distance, "closest board distance [m]");
  app.add_option("--max-distance", flags.max_distance, "farthest board distance [m]");
  app.add_option("--seed", flags.seed, "random seed")->capture_default_str();
  app.add_flag("--no-clutter", flags.no_clutter, "no floor and walls");
  app.add_flag("--no-lidar-seeds", flags.no_lidar_seeds,
               "write no lidar_seed per pair: the board is found in each cloud by itself, as in a "
               "user's dataset");
  app.add_flag("--board-only-clouds", flags.board_only_clouds,
               "clouds cropped to the board's returns, without rings (as some public sets ship "
               "them)");
  app.add_flag("--lidar-viewpoints", flags.lidar_viewpoints,
               "each return's ray origin in the clouds (fields vp_x, vp_y, vp_z: a swept "
               "scanner's mirror as its stage turned it), as a driver that knows it writes them");
}

bool BuildSimOptions(const SimFlags& flags, SimOptions* options, std::string* why) {
  try {
    *options = SimPreset(flags.preset);
  } catch (const std::exception& e) {
    *why = e.what();
    return false;
  }
  if (!flags.lidar.empty()) {
    const auto lidar = ParseLidarModelName(flags.lidar);
    if (!lidar) {
      *why = "unknown --lidar '" + flags.lidar + "' (" + LidarModelNames() + ")";
      return false;
    }
    options->lidar = *lidar;
  }
  if (!flags.camera.empty()) {
    if (flags.camera != "pinhole" && flags.camera != "fisheye") {
      *why = "unknown --camera '" + flags.camera + "' (pinhole, fisheye)";
      return false;
    }
    options->fisheye = flags.camera == "fisheye";
    options->camera = CameraModel{};  // the default camera of that kind
    options->camera.width = 0;
  }
  if (!flags.image_size.empty()) {
    int width = 0, height = 0;
    char x = 0, rest = 0;
    if (std::sscanf(flags.image_size.c_str(), "%d%c%d%c", &width, &x, &height, &rest) != 3 ||
        x != 'x' || width < 64 || height < 64 || width > 20000 || height > 20000) {
      *why = "--image-size must be WxH with sides in [64, 20000], got '" + flags.image_size + "'";
      return false;
    }
    // The default camera of the chosen kind, its focal length scaled with the width.
    CameraModel camera =
        options->camera.width ? options->camera : DefaultSimCamera(options->fisheye);
    const double scale = static_cast<double>(width) / camera.width;
    camera.fx *= scale;
    camera.fy *= scale;
    camera.cx = 0.5 * (width - 1);
    camera.cy = 0.5 * (height - 1);
    camera.width = width;
    camera.height = height;
    options->camera = camera;
  }
  if (!flags.board.empty()) {
    try {
      options->board = BoardPreset(flags.board);
    } catch (const std::exception& e) {
      *why = e.what();
      return false;
    }
  }
  if (flags.pairs > 0) options->num_pairs = flags.pairs;
  if (flags.lidar_noise >= 0) options->lidar_range_noise_m = flags.lidar_noise;
  options->lidar_range_offset_m = flags.lidar_range_offset;
  options->lidar_angular_noise_rad = flags.lidar_angular_noise_deg * kDegToRad;
  if (flags.lidar_frame > 0) options->lidar_frame_s = flags.lidar_frame;
  if (flags.image_noise >= 0) options->image_noise = flags.image_noise;
  if (flags.min_distance > 0) options->min_distance_m = flags.min_distance;
  if (flags.max_distance > 0) options->max_distance_m = flags.max_distance;
  options->seed = flags.seed;
  if (flags.no_clutter) options->clutter = false;
  if (flags.board_only_clouds) options->board_only_clouds = true;
  if (flags.lidar_viewpoints) options->lidar_viewpoints = true;
  if (flags.no_lidar_seeds) options->lidar_seeds = false;
  return options->Check(why);
}

int RunSimulate(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--kind" || std::string(argv[i]).rfind("--kind=", 0) == 0)
      return RunSimulateLrf(argc, argv);
  CLI::App app{
      "Write a synthetic LiDAR + camera dataset (PCD, PNG, dataset.json) with ground truth.",
      "calibench simulate"};
  app.footer(
      "The 2D laser rangefinder kind: `calibench simulate --kind lrf --out DIR` writes a 2D LRF + "
      "depth camera dataset with the three-face target (manifest.json, scans/, depth/), with "
      "--preset paper|ideal, --observations N (target poses, default 20), --range-noise M, "
      "--disparity-noise PX, --min-distance / --max-distance M, --seed, --stereo (a right depth "
      "camera 0.12 m to the right, for `evaluate --stereo`), --no-clutter. "
      "`calibench simulate --kind lrf --help` shows them with their defaults.");
  std::string out_dir;
  app.add_option("--out,-o", out_dir, "output folder")->required();
  SimFlags flags;
  AddSimFlags(app, flags);
  bool rig = false;
  double second_yaw_deg = RigSimOptions{}.second_camera_yaw_deg;
  app.add_flag("--rig", rig,
               "a rig instead: the camera (cam0) and a fisheye (cam1) turned aside, in the rig's "
               "folder form (cameras/, images/<camera>/, clouds/, target.json; --pairs captures)");
  app.add_option("--second-camera-yaw", second_yaw_deg,
                 "with --rig: how far cam1 is turned to the left of cam0 (degrees)")
      ->capture_default_str();
  double wave_s = 0.0;
  WaveOptions wave;
  app.add_option("--wave", wave_s,
                 "a waved board instead: this many seconds of a board never still (an ellipse in "
                 "front of the camera at --wave-speed), each sweep that sees it a pair with "
                 "every camera frame around it (\"images\"), each return at its own time [s]");
  app.add_option("--wave-speed", wave.speed_mps, "with --wave: the board's speed [m/s]")
      ->capture_default_str();
  app.add_option("--camera-minus-lidar", wave.camera_minus_lidar_s,
                 "with --wave: the camera's stamps minus the LiDAR's clock [s] (+0.04: 40 ms late)")
      ->capture_default_str();
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  SimOptions options;
  std::string why;
  if (!BuildSimOptions(flags, &options, &why)) {
    std::fprintf(stderr, "calibench simulate: %s\n", why.c_str());
    return kUsage;
  }
  if (rig) {
    RigSimOptions rig_options;
    rig_options.base = options;
    rig_options.num_captures = options.num_pairs;
    rig_options.second_camera_yaw_deg = second_yaw_deg;
    if (!rig_options.Check(&why)) {
      std::fprintf(stderr, "calibench simulate: --rig: %s\n", why.c_str());
      return kUsage;
    }
    const RigSimTruth truth = SimulateRigFolder(rig_options, out_dir);
    std::printf("wrote a rig of 2 cameras, %d captures (%d seen by both), to %s\n",
                rig_options.num_captures, truth.shared_captures, out_dir.c_str());
    return kOk;
  }
  if (wave_s > 0) {
    wave.rig = options;
    wave.duration_s = wave_s;
    if (!wave.Check(&why)) {
      std::fprintf(stderr, "calibench simulate: --wave: %s\n", why.c_str());
      return kUsage;
    }
    const WavedDataset waved = SimulateWavedDataset(wave, out_dir);
    std::printf(
        "wrote %zu pairs of a board waved at %.2f m/s (median) for %.1f s, %d sweeps and %d "
        "frames, the camera's stamps %+.0f ms off, to %s\n",
        waved.dataset.pairs.size(), waved.median_speed_mps, wave_s, waved.sweeps, waved.frames,
        wave.camera_minus_lidar_s * 1e3, waved.dataset.manifest.string().c_str());
    return kOk;
  }
  const Dataset dataset = SimulateDataset(options, out_dir);
  std::printf("wrote %zu pairs (%s, %s camera) to %s\n", dataset.pairs.size(),
              LidarModelName(options.lidar).c_str(), CameraModelName(dataset.camera.type).c_str(),
              dataset.manifest.string().c_str());
  return kOk;
}

}  // namespace calibench::app
