#include "core/evaluation/check_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <random>

#include "core/base/parallel.h"
#include "core/io/camera_file.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/results/result_file.h"
#include "core/results/result_json.h"
#include "core/sim/sim.h"
#include "core/sim/textured_scene.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
constexpr double kChi2Six95 = 12.59;  // the 95 % quantile of χ² with 6 degrees of freedom

bool IsRisley(const std::string& lidar) {
  return lidar == "mid40" || lidar == "avia" || lidar == "mid360";
}

std::optional<LidarModel> SpinningModel(const std::string& lidar) {
  if (lidar == "vlp16") return LidarModel::kVlp16;
  if (lidar == "os0-128") return LidarModel::kOs0_128;
  if (lidar == "hdl64") return LidarModel::kHdl64;
  return std::nullopt;
}

Pose RigPose(double x, double y, double z, double yaw_deg, double pitch_deg, double roll_deg) {
  Pose pose = Pose::Identity();
  pose.linear() = (Eigen::AngleAxisd(yaw_deg * kDegToRad, Vec3::UnitZ()) *
                   Eigen::AngleAxisd(pitch_deg * kDegToRad, Vec3::UnitY()) *
                   Eigen::AngleAxisd(roll_deg * kDegToRad, Vec3::UnitX()))
                      .toRotationMatrix();
  pose.translation() = Vec3(x, y, z);
  return pose;
}

// Where the LiDAR stands for each frame (world frame of MakeTexturedRoom, looking along +x).
std::vector<Pose> RigPoses(const CheckSweepOptions& options, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Pose> poses;
  if (!options.moving) {
    const Pose still = RigPose(-1.5 + 0.5 * u(rng), 0.5 * u(rng), 1.3, 20.0 * u(rng), 0, 0);
    poses.assign(options.frames, still);
    return poses;
  }
  const double phase = M_PI * u(rng);
  for (int k = 0; k < options.frames; ++k) {
    const double along = options.frames > 1 ? static_cast<double>(k) / (options.frames - 1) : 0.5;
    poses.push_back(RigPose(-2.5 + 5.0 * along, 0.4 * std::sin(3.0 * along + phase), 1.3,
                            25.0 * std::sin(0.9 * k + phase), 2.0 * u(rng), 2.0 * u(rng)));
  }
  return poses;
}

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v(n(rng), n(rng), n(rng));
  return v.normalized();
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct Trial {
  std::string error;
  Vec6 delta = Vec6::Zero();  // R = truth moved by this (camera axes)
};

std::vector<Trial> Trials(const CheckSweepOptions& options, std::mt19937_64& rng) {
  std::vector<Trial> trials = {{"none", Vec6::Zero()}};
  char label[32];
  for (double deg : options.rotation_errors_deg) {
    Trial t;
    std::snprintf(label, sizeof label, "%g deg", deg);
    t.error = label;
    t.delta.tail<3>() = deg * kDegToRad * RandomUnit(rng);
    trials.push_back(t);
  }
  for (double m : options.translation_errors_m) {
    Trial t;
    std::snprintf(label, sizeof label, "%g cm", m * 100.0);
    t.error = label;
    t.delta.head<3>() = m * RandomUnit(rng);
    trials.push_back(t);
  }
  return trials;
}

}  // namespace

bool CheckSweepOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (!IsRisley(lidar) && !SpinningModel(lidar))
    return fail("unknown LiDAR \"" + lidar + "\" (known: vlp16, os0-128, hdl64, " +
                RisleyPatternNames() + ")");
  if (seeds < 1 || frames < 1) return fail("at least one seed and one frame");
  if (!(range_noise_m >= 0 && image_noise >= 0)) return fail("noise must be >= 0");
  if (!(livox_hold_s > 0 && livox_hold_s <= 10)) return fail("a Livox hold must be in (0, 10] s");
  for (double e : rotation_errors_deg)
    if (!(e > 0 && e < 10)) return fail("rotation errors must be in (0, 10) deg");
  for (double e : translation_errors_m)
    if (!(e > 0 && e < 1)) return fail("translation errors must be in (0, 1) m");
  return check.Check(why);
}

CameraModel CheckSweepCamera() {
  CameraModel camera;
  camera.type = CameraModelType::kPinholeRadTan;
  camera.width = 1280;
  camera.height = 960;
  camera.fx = camera.fy = 900.0;
  camera.cx = 639.5;
  camera.cy = 479.5;
  camera.distortion = {-0.05, 0.02, 0.0, 0.0, 0.0};
  return camera;
}

SimulatedCheckScene SimulateCheckScene(const CheckSweepOptions& options, std::uint64_t seed) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("check sweep: " + why);
  std::mt19937_64 rng(seed * 7919 + 17);
  TexturedRoomOptions room;
  room.seed = seed;
  const TexturedScene scene = MakeTexturedRoom(room);
  SimulatedCheckScene out;
  out.camera = CheckSweepCamera();
  out.cam_from_lidar = DefaultCamFromLidar();
  const Pose lidar_from_cam = out.cam_from_lidar.inverse();
  const std::vector<Pose> rig = RigPoses(options, rng);
  const std::optional<LidarModel> spinning = SpinningModel(options.lidar);
  const BeamTable beams = spinning ? MakeBeamTable(*spinning) : BeamTable{};
  const RisleyPattern pattern = spinning ? RisleyPattern{} : MakeRisleyPattern(options.lidar);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  for (int k = 0; k < options.frames; ++k) {
    SimulatedCheckFrame frame;
    char id[16];
    std::snprintf(id, sizeof id, "%04d", k);
    frame.id = id;
    SceneScanOptions scan;
    scan.range_noise_m = options.range_noise_m;
    scan.seed = seed * 1000 + k;
    if (spinning) {
      scan.azimuth_offset_rad = phase(rng);
      frame.cloud = ScanSceneWithBeams(beams, rig[k], scene, scan);
    } else {
      scan.start_s = k * options.livox_hold_s;
      scan.duration_s = options.livox_hold_s;
      frame.cloud = ScanSceneWithRisley(pattern, rig[k], scene, scan);
    }
    SceneImageOptions render;
    render.image_noise = options.image_noise;
    render.seed = seed * 1000 + k;
    render.threads = options.threads;
    frame.image = RenderSceneImage(out.camera, rig[k] * lidar_from_cam, scene, render);
    out.frames.push_back(std::move(frame));
  }
  return out;
}

void WriteCheckScene(const SimulatedCheckScene& scene, const fs::path& dir) {
  fs::create_directories(dir / "clouds");
  fs::create_directories(dir / "images");
  for (const SimulatedCheckFrame& frame : scene.frames) {
    SavePcd(dir / "clouds" / (frame.id + ".pcd"), frame.cloud);
    SaveImage(dir / "images" / (frame.id + ".png"), frame.image);
  }
  SaveCameraFile(dir / "camera.yaml", scene.camera, CameraFileFormat::kRosCameraInfo);
  nlohmann::json truth =
      ResultHeaderJson(ResultNames{}, scene.cam_from_lidar, Mat6::Zero(), ObservabilityReport{});
  truth["method"] = "simulation";
  truth["provenance"] = {{"kind", "simulation"},
                         {"text", "the simulator's ground truth (calibench check-sweep)"}};
  truth["pairs"] = nlohmann::json::array();
  WriteResultJson(dir / "truth.result.json", truth);
}

CheckSweepResult RunCheckSweep(const CheckSweepOptions& options,
                               const CheckSweepProgress& progress) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("check sweep: " + why);
  CheckSweepResult result;
  result.options = options;
  std::vector<std::vector<double>> chi2s, errors_deg, errors_mm;
  double check_seconds = 0.0;
  int checks = 0;
  for (int s = 0; s < options.seeds; ++s) {
    const std::uint64_t seed = options.first_seed + s;
    const SimulatedCheckScene scene = SimulateCheckScene(options, seed);
    std::vector<EdgeFrame> frames(scene.frames.size());
    ParallelFor(frames.size(), options.threads > 0 ? options.threads : DefaultThreads(),
                [&](size_t i) {
                  frames[i] = MakeEdgeFrame(scene.frames[i].id, scene.frames[i].cloud,
                                            scene.frames[i].image, options.check);
                });
    std::mt19937_64 rng(seed * 104729 + 3);
    const std::vector<Trial> trials = Trials(options, rng);
    if (result.rows.empty()) {
      for (const Trial& t : trials) result.rows.push_back(CheckSweepRow{t.error});
      chi2s.resize(trials.size());
      errors_deg.resize(trials.size());
      errors_mm.resize(trials.size());
    }
    for (size_t t = 0; t < trials.size(); ++t) {
      const Pose reference = PerturbOnCameraAxes(scene.cam_from_lidar, trials[t].delta);
      const auto start = std::chrono::steady_clock::now();
      const CheckReport report =
          CheckCalibration(frames, scene.camera, reference, Mat6::Zero(), options.check);
      check_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      ++checks;
      CheckSweepRow& row = result.rows[t];
      ++row.trials;
      row.miscalibrated += report.verdict == CheckVerdict::kMiscalibrated;
      row.consistent += report.verdict == CheckVerdict::kConsistent;
      row.cannot_tell += report.verdict == CheckVerdict::kCannotTell;
      if (!report.has_estimate) continue;
      ++row.with_estimate;
      row.significant += report.change_sigmas > options.check.significance_sigma;
      const Vec6 error = DeltaOnCameraAxes(scene.cam_from_lidar, report.estimate);
      const double chi2 = error.dot(report.covariance.ldlt().solve(error));
      chi2s[t].push_back(chi2);
      row.covered += chi2 < kChi2Six95;
      errors_deg[t].push_back(error.tail<3>().norm() / kDegToRad);
      errors_mm[t].push_back(error.head<3>().norm() * 1e3);
    }
    if (progress) progress(s + 1, options.seeds);
  }
  for (size_t t = 0; t < result.rows.size(); ++t) {
    CheckSweepRow& row = result.rows[t];
    double sum = 0.0;
    for (double c : chi2s[t]) sum += c;
    row.mean_chi2 = chi2s[t].empty() ? 0.0 : sum / chi2s[t].size();
    row.median_error_deg = Median(errors_deg[t]);
    row.median_error_mm = Median(errors_mm[t]);
  }
  result.seconds_per_check = checks ? check_seconds / checks : 0.0;
  return result;
}

std::string FormatCheckSweep(const CheckSweepResult& result) {
  const CheckSweepOptions& o = result.options;
  std::string text;
  char line[256];
  std::snprintf(line, sizeof line,
                "targetless check on simulated textured rooms: %s, %s rig, %d seeds x %d frames\n"
                "(tolerance %.2f deg / %.0f mm; caught = verdict miscalibrated; significant = "
                "change beyond %.0f sigma)\n",
                o.lidar.c_str(), o.moving ? "moving" : "still", o.seeds, o.frames,
                o.check.tolerance_deg, o.check.tolerance_m * 1e3, o.check.significance_sigma);
  text += line;
  text +=
      "error      trials  miscal.  consist.  cannot  signif.  chi2/6  covered  err deg  err mm\n";
  for (const CheckSweepRow& r : result.rows) {
    std::snprintf(
        line, sizeof line, "%-9s  %6d  %7d  %8d  %6d  %7d  %6.2f  %4d/%-3d  %7.3f  %6.1f\n",
        r.error.c_str(), r.trials, r.miscalibrated, r.consistent, r.cannot_tell, r.significant,
        r.mean_chi2 / 6.0, r.covered, r.with_estimate, r.median_error_deg, r.median_error_mm);
    text += line;
  }
  std::snprintf(line, sizeof line, "%.1f s per check\n", result.seconds_per_check);
  text += line;
  return text;
}

std::string CheckSweepJson(const CheckSweepResult& result) {
  const CheckSweepOptions& o = result.options;
  nlohmann::json rows = nlohmann::json::array();
  for (const CheckSweepRow& r : result.rows)
    rows.push_back({{"error", r.error},
                    {"trials", r.trials},
                    {"miscalibrated", r.miscalibrated},
                    {"consistent", r.consistent},
                    {"cannot_tell", r.cannot_tell},
                    {"significant", r.significant},
                    {"with_estimate", r.with_estimate},
                    {"covered_95", r.covered},
                    {"mean_chi2", r.mean_chi2},
                    {"median_error_deg", r.median_error_deg},
                    {"median_error_mm", r.median_error_mm}});
  const nlohmann::json root = {{"lidar", o.lidar},
                               {"moving", o.moving},
                               {"seeds", o.seeds},
                               {"frames", o.frames},
                               {"tolerance_deg", o.check.tolerance_deg},
                               {"tolerance_m", o.check.tolerance_m},
                               {"rows", rows},
                               {"seconds_per_check", result.seconds_per_check}};
  return root.dump();
}

}  // namespace calibench
