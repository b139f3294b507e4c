#include "core/sim/sim_wave.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "core/base/parallel.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar/board_returns.h"

namespace calibench {
namespace {

// The recording's first instant on the LiDAR's clock (a real epoch time: stamps keep their size).
constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000LL;

std::int64_t Ns(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * 1e9)); }

std::string Numbered(const char* stem, int index, const char* extension) {
  char name[48];
  std::snprintf(name, sizeof(name), "%s%05d%s", stem, index, extension);
  return name;
}

// The room the waving happens in, as the still simulator's (core/sim/sim.cpp RoomScene).
LidarScene WaveRoom(const SimOptions& r) {
  LidarScene scene;
  scene.clutter = r.clutter;
  scene.floor_z_m = r.lidar == LidarModel::kHdl64 ? -1.73 : -1.5;
  scene.wall_distance_m = 6.0;
  return scene;
}

struct Sweep {
  std::int64_t stamp_ns = 0;
  bool board_seen = false;
  SimPairTruth truth;  // the board at its returns' median time
};

}  // namespace

bool WaveOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (!rig.Check(why)) return false;
  const BeamTable beams = MakeBeamTable(rig.lidar);
  if (beams.Fired() && !beams.risley)
    return fail("a waved board is simulated for spinning LiDARs and Risley patterns");
  if (!(duration_s > 0) || !(speed_mps > 0) || !(lidar_hz > 0) || !(camera_hz > 0))
    return fail("the wave's duration, speed and rates must be > 0");
  if (!(centre_distance_m > depth_m + 0.5) || !(across_m >= 0) || !(depth_m >= 0))
    return fail("the wave must stay at least 0.5 m in front of the camera");
  if (!(max_tilt_deg >= 0 && max_tilt_deg < 80)) return fail("max_tilt_deg must be in [0, 80)");
  if (!(images_window_s > 0)) return fail("images_window_s must be > 0");
  if (!std::isfinite(camera_minus_lidar_s)) return fail("camera_minus_lidar_s must be finite");
  if (min_board_returns < 1) return fail("min_board_returns must be >= 1");
  return true;
}

Pose WavedCamFromBoard(const WaveOptions& o, double t) {
  // An ellipse at constant angular rate: the speed stays within the two half-axes' ratio of
  // speed_mps, never a stop.
  const double radius = std::max(0.05, 0.5 * (o.across_m + o.depth_m));
  const double w = o.speed_mps / radius;
  const double tilt = o.max_tilt_deg * kDegToRad;
  Pose pose = Pose::Identity();
  pose.translation() = Vec3(o.across_m * std::cos(w * t), 0.08 * std::sin(1.7 * w * t + 0.4),
                            o.centre_distance_m + o.depth_m * std::sin(w * t));
  pose.linear() = (Eigen::AngleAxisd(0.8 * tilt * std::sin(0.83 * w * t + 1.1), Vec3::UnitX()) *
                   Eigen::AngleAxisd(tilt * std::sin(0.61 * w * t + 0.3), Vec3::UnitY()))
                      .toRotationMatrix();
  return pose;
}

namespace {

// The camera's frames at their true instants, stamped on the camera's clock.
std::vector<StampedImage> RenderFrames(const WaveOptions& options, const SimOptions& r,
                                       const std::filesystem::path& root, int frames) {
  std::vector<StampedImage> images(frames);
  ParallelFor(frames, DefaultThreads(), [&](size_t k) {
    const double t = (static_cast<double>(k) + 0.37) / options.camera_hz;
    RenderOptions render;
    render.image_noise = r.image_noise;
    render.seed = r.seed * 1'000'003 + k;
    images[k] = {root / "images" / Numbered("frame_", static_cast<int>(k), ".png"),
                 kStartNs + Ns(t + options.camera_minus_lidar_s)};
    SaveImage(images[k].image,
              RenderBoardImage(r.camera, r.board, WavedCamFromBoard(options, t), render));
  });
  return images;
}

// Sweep `j`, each return at its own time with the board where it was then; its cloud written
// (clouds/sweep_<j>.pcd) and the bound's truth kept when it sees the board.
Sweep SimulateSweep(const WaveOptions& options, const SimOptions& r, const BeamTable& beams,
                    const BoardPrint& print, int j, const std::filesystem::path& root) {
  const double sweep_s = 1.0 / options.lidar_hz;
  const double start = j * sweep_s;
  const Pose lidar_from_cam = r.cam_from_lidar.inverse();
  std::mt19937_64 rng(r.seed * 7919 + j);
  LidarScene scene = WaveRoom(r);
  scene.lidar_from_board_at = [&](double s) {
    return lidar_from_cam * WavedCamFromBoard(options, start + s);
  };
  scene.lidar_from_board = scene.lidar_from_board_at(0.5 * sweep_s);
  LidarScanOptions scan;
  scan.range_noise_m = r.lidar_range_noise_m;
  scan.range_offset_m = r.lidar_range_offset_m;
  scan.angular_noise_rad = r.lidar_angular_noise_rad;
  // A spinning LiDAR's firing phase drifts from sweep to sweep; a Risley pattern's rosette goes
  // on where the last frame left it (BeamRays reads its phase as seconds into the pattern).
  scan.azimuth_offset_rad =
      beams.risley ? 2.0 * M_PI * std::fmod(start, 1.0)
                   : beams.PhaseSpanRad() * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  scan.seed = rng();
  scan.sweep_s = sweep_s;
  const LidarScan lidar = SimulateLidarScan(beams, print, scene, scan);
  std::vector<float> board_times;
  for (size_t i = 0; i < lidar.size(); ++i)
    if (lidar.surface[i] == SimSurface::kBoard) board_times.push_back(lidar.time_s[i]);
  Sweep sweep;
  sweep.stamp_ns = kStartNs + Ns(start);
  sweep.board_seen = static_cast<int>(board_times.size()) >= options.min_board_returns;
  const std::filesystem::path cloud = root / "clouds" / Numbered("sweep_", j, ".pcd");
  if (options.every_sweep || sweep.board_seen)
    SavePcd(cloud, lidar.ToCloud(r.board_only_clouds, r.lidar_viewpoints), PcdEncoding::kBinary);
  if (!sweep.board_seen) return sweep;
  std::nth_element(board_times.begin(), board_times.begin() + board_times.size() / 2,
                   board_times.end());
  sweep.truth.cam_from_board =
      WavedCamFromBoard(options, start + board_times[board_times.size() / 2]);
  const LidarRectangle sheet{lidar_from_cam * sweep.truth.cam_from_board,
                             0.5 * Vec2(r.board.SheetWidth(), r.board.SheetHeight())};
  sweep.truth.lidar_board_points = CastBoardReturns(beams, sheet, scan.azimuth_offset_rad).points;
  return sweep;
}

}  // namespace

WavedDataset SimulateWavedDataset(const WaveOptions& options,
                                  const std::filesystem::path& out_dir) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("wave: " + why);
  const SimOptions r = ResolveSimOptions(options.rig);
  BeamTable beams = MakeBeamTable(r.lidar);
  if (beams.risley) beams.frame_s = 1.0 / options.lidar_hz;  // a frame per sweep
  const BoardPrint print(r.board);
  const std::filesystem::path root = std::filesystem::absolute(out_dir);
  std::filesystem::create_directories(root / "clouds");
  std::filesystem::create_directories(root / "images");

  const int frames = static_cast<int>(std::floor(options.duration_s * options.camera_hz));
  const std::vector<StampedImage> images = RenderFrames(options, r, root, frames);
  const double sweep_s = 1.0 / options.lidar_hz;
  const int sweeps = static_cast<int>(std::floor(options.duration_s * options.lidar_hz));
  std::vector<Sweep> seen(sweeps);
  ParallelFor(sweeps, DefaultThreads(), [&](size_t j) {
    seen[j] = SimulateSweep(options, r, beams, print, static_cast<int>(j), root);
  });

  WavedDataset out;
  out.sweeps = sweeps;
  out.frames = frames;
  out.frame_files = images;
  for (int j = 0; j < sweeps; ++j)
    if (options.every_sweep || seen[j].board_seen)
      out.sweep_files.emplace_back(root / "clouds" / Numbered("sweep_", j, ".pcd"),
                                   kStartNs + Ns(j * sweep_s));
  Dataset& dataset = out.dataset;
  dataset.manifest = root / "dataset.json";
  dataset.camera = r.camera;
  dataset.target = r.board;
  dataset.lidar_rings = beams.HasRings() ? static_cast<int>(beams.elevations_rad.size()) : 0;
  dataset.cam_from_lidar_ground_truth = r.cam_from_lidar;
  for (int j = 0; j < sweeps; ++j) {
    if (!seen[j].board_seen) continue;
    PairEntry pair;
    pair.id = Numbered("", j, "");
    pair.cloud = root / "clouds" / Numbered("sweep_", j, ".pcd");
    pair.lidar_stamp_ns = seen[j].stamp_ns;
    // Every frame within the window of the sweep, as an import keeps them (stamps compared as
    // the two clocks give them: the offset is not known).
    // One frame period beyond the window each side, so that every instant the window reaches
    // lies between two kept frames.
    const std::int64_t window = Ns(options.images_window_s + 1.0 / options.camera_hz);
    for (const StampedImage& frame : images)
      if (frame.stamp_ns >= seen[j].stamp_ns - window &&
          frame.stamp_ns <= seen[j].stamp_ns + Ns(sweep_s) + window)
        pair.images.push_back(frame);
    if (pair.images.empty()) continue;
    pair.image = std::min_element(pair.images.begin(), pair.images.end(),
                                  [&](const StampedImage& a, const StampedImage& b) {
                                    return std::llabs(a.stamp_ns - seen[j].stamp_ns) <
                                           std::llabs(b.stamp_ns - seen[j].stamp_ns);
                                  })
                     ->image;
    dataset.pairs.push_back(pair);
    out.truth.push_back(seen[j].truth);
  }
  SaveDataset(dataset.manifest, dataset);
  std::vector<double> speeds;
  for (int k = 0; k + 1 < frames; ++k) {
    const double t = (k + 0.37) / options.camera_hz, dt = 1.0 / options.camera_hz;
    speeds.push_back((WavedCamFromBoard(options, t + dt).translation() -
                      WavedCamFromBoard(options, t).translation())
                         .norm() /
                     dt);
  }
  if (!speeds.empty()) {
    std::nth_element(speeds.begin(), speeds.begin() + speeds.size() / 2, speeds.end());
    out.median_speed_mps = speeds[speeds.size() / 2];
  }
  return out;
}

}  // namespace calibench
