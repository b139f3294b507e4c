// Simulated datasets: options, presets, board placement and the files of SimulateDataset.
#include "core/sim/sim.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lidar/board_returns.h"
#include "core/lidar/cloud.h"

namespace calibench {
namespace {

constexpr double kImageMarginFraction = 0.05;  // of the image width, around the whole sheet
// Simulated boards are placed where the LiDAR's returns leave a margin over what finding the
// board needs (guidance's BoardReturnsRule asks for 40 returns): 4 rings of 3+ returns, 60 in all
// (a Livox-class scanner has no rings: 60 returns on the sheet, however its rosette lays them).
constexpr BoardReturnsRule kSimulatedBoardReturns{4, 3, 60};
constexpr double kMaxIncidenceDeg = 80.0;  // LiDAR ray vs. board normal at the board centre
constexpr int kMaxTriesPerPair = 5000;

// The simulated LiDAR's rays: its model's table, a Livox-class pattern fired for the options'
// frame (one cloud's worth of returns).
BeamTable SimBeamTable(const SimOptions& options) {
  BeamTable beams = MakeBeamTable(options.lidar);
  beams.frame_s = options.lidar_frame_s;
  return beams;
}

// Independent, well-mixed seeds per pair and purpose (SplitMix64 finaliser).
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t pair, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (pair * 4 + stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The options with every "0 = default" field replaced by its value.
SimOptions Resolve(const SimOptions& options) {
  SimOptions r = options;
  if (r.camera.width == 0) r.camera = DefaultSimCamera(r.fisheye);
  if (r.board.cols == 0) r.board = BoardPreset("a3");
  r.board.board_width = r.board.SheetWidth();
  r.board.board_height = r.board.SheetHeight();
  if (r.cam_from_lidar.matrix() == Mat4::Identity()) r.cam_from_lidar = DefaultCamFromLidar();
  if (r.seed_radius_m == 0.0) {
    r.seed_radius_m = 0.4 * std::min(r.board.SheetWidth(), r.board.SheetHeight());
  }
  return r;
}

// The room around the LiDAR: the floor by mount height, the walls beyond the farthest board.
LidarScene RoomScene(const SimOptions& r) {
  LidarScene scene;
  scene.clutter = r.clutter;
  scene.floor_z_m = r.lidar == LidarModel::kHdl64 ? -1.73 : -1.5;  // car roof vs. tripod
  const double half_diagonal = 0.5 * std::hypot(r.board.SheetWidth(), r.board.SheetHeight());
  const double camera_offset = r.cam_from_lidar.inverse().translation().norm();
  scene.wall_distance_m = std::max(6.0, r.max_distance_m + half_diagonal + camera_offset + 1.0);
  return scene;
}

// One pair's board placement and the firing phase of its sweep.
struct PairPlan {
  Pose cam_from_board;
  double azimuth_offset_rad = 0.0;
};

Pose RandomBoardPose(const SimOptions& r, const Vec3& bearing, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double distance = r.min_distance_m + (r.max_distance_m - r.min_distance_m) * unit(rng);
  // Facing the camera: board z along the viewing ray (away from the camera), x near camera x.
  const Vec3 z = bearing.normalized();
  const Vec3 x = (Vec3::UnitX() - Vec3::UnitX().dot(z) * z).normalized();
  Mat3 facing;
  facing << x, z.cross(x), z;
  const double tilt = r.max_tilt_deg * kDegToRad * unit(rng);
  const double tilt_axis_angle = 2.0 * M_PI * unit(rng);
  const Vec3 tilt_axis = std::cos(tilt_axis_angle) * x + std::sin(tilt_axis_angle) * z.cross(x);
  const double roll = M_PI * (2.0 * unit(rng) - 1.0);
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(tilt, tilt_axis).toRotationMatrix() * facing *
                  Eigen::AngleAxisd(roll, Vec3::UnitZ()).toRotationMatrix();
  pose.translation() = distance * z;
  return pose;
}

// The sheet boundary (board frame), densely enough to follow distortion curves.
std::vector<Vec3> SheetOutline(const BoardSpec& board) {
  const double hw = 0.5 * board.SheetWidth(), hh = 0.5 * board.SheetHeight();
  const Vec3 corners[5] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}, {-hw, -hh, 0}};
  constexpr int kPerEdge = 16;
  std::vector<Vec3> outline;
  for (int e = 0; e < 4; ++e) {
    for (int k = 0; k < kPerEdge; ++k) {
      outline.push_back(corners[e] + (corners[e + 1] - corners[e]) * k / kPerEdge);
    }
  }
  return outline;
}

bool SheetInImage(const SimOptions& r, const Pose& cam_from_board) {
  const double margin = kImageMarginFraction * r.camera.width;
  for (const Vec3& p : SheetOutline(r.board)) {
    const Vec3 in_cam = cam_from_board * p;
    if (in_cam.z() <= 0.05) return false;
    const auto pixel = r.camera.Project(in_cam);
    if (!pixel || !r.camera.InImage(*pixel, margin)) return false;
  }
  return true;
}

// Above the floor, inside the walls, and the print seen by the LiDAR at a usable incidence.
bool SheetFitsRoom(const SimOptions& r, const LidarScene& scene, const Pose& lidar_from_board) {
  const Vec3 to_lidar = -lidar_from_board.translation();
  const Vec3 normal = lidar_from_board.linear().col(2);  // away from the print's viewer
  if (-normal.dot(to_lidar.normalized()) < std::cos(kMaxIncidenceDeg * kDegToRad)) return false;
  if (!scene.clutter) return true;
  const double hw = 0.5 * r.board.SheetWidth(), hh = 0.5 * r.board.SheetHeight();
  for (const Vec3& c : {Vec3(-hw, -hh, 0), Vec3(hw, -hh, 0), Vec3(hw, hh, 0), Vec3(-hw, hh, 0)}) {
    const Vec3 p = lidar_from_board * c;
    if (p.z() < scene.floor_z_m + 0.1) return false;
    if (std::abs(p.x()) > scene.wall_distance_m - 0.2) return false;
    if (std::abs(p.y()) > scene.wall_distance_m - 0.2) return false;
  }
  return true;
}

// The whole sheet within the LiDAR's vertical field of view: a "valid measurement" in the sense
// of Ca²Lib Section 4.1, where both sensors see the complete target.
bool SheetInLidarFov(const SimOptions& r, const BeamTable& beams, const Pose& lidar_from_board) {
  const double hw = 0.5 * r.board.SheetWidth(), hh = 0.5 * r.board.SheetHeight();
  for (const Vec3& c : {Vec3(-hw, -hh, 0), Vec3(hw, -hh, 0), Vec3(hw, hh, 0), Vec3(-hw, hh, 0)})
    if (!beams.InField(lidar_from_board * c)) return false;
  return true;
}

// The noise-free returns of the board alone (no room).
// The sheet's noise-free returns with nothing in front of it: the ray caster guidance predicts
// with.
BoardReturns ScanBoardOnly(const BeamTable& beams, const BoardPrint& print,
                           const Pose& lidar_from_board, double azimuth_offset_rad) {
  LidarRectangle sheet;
  sheet.lidar_from_rectangle = lidar_from_board;
  sheet.half_size_m = 0.5 * Vec2(print.board().SheetWidth(), print.board().SheetHeight());
  return CastBoardReturns(beams, sheet, azimuth_offset_rad);
}

// Where a user would brush: the centroid of the noise-free board returns.
Vec3 BoardHitCentroid(const BeamTable& beams, const BoardPrint& print, const Pose& lidar_from_board,
                      double azimuth_offset_rad) {
  const BoardReturns hits = ScanBoardOnly(beams, print, lidar_from_board, azimuth_offset_rad);
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : hits.points) centroid += p / static_cast<double>(hits.points.size());
  return hits.points.empty() ? lidar_from_board.translation() : centroid;
}

bool EnoughLidarHits(const BeamTable& beams, const BoardPrint& print, const Pose& lidar_from_board,
                     double azimuth_offset_rad) {
  return kSimulatedBoardReturns.Met(
      ScanBoardOnly(beams, print, lidar_from_board, azimuth_offset_rad));
}

PairPlan PlanPair(const SimOptions& r, const BeamTable& beams, const BoardPrint& print,
                  const LidarScene& scene, int pair) {
  std::mt19937_64 rng(MixSeed(r.seed, pair, 0));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  PairPlan plan;
  plan.azimuth_offset_rad = beams.PhaseSpanRad() * unit(rng);
  const double margin = kImageMarginFraction * r.camera.width;
  const Pose lidar_from_cam = r.cam_from_lidar.inverse();
  for (int attempt = 0; attempt < kMaxTriesPerPair; ++attempt) {
    const Vec2 centre_pixel(margin + (r.camera.width - 1 - 2 * margin) * unit(rng),
                            margin + (r.camera.height - 1 - 2 * margin) * unit(rng));
    const auto bearing = r.camera.Unproject(centre_pixel);
    if (!bearing) continue;
    plan.cam_from_board = RandomBoardPose(r, *bearing, rng);
    const Pose lidar_from_board = lidar_from_cam * plan.cam_from_board;
    if (SheetInImage(r, plan.cam_from_board) && SheetFitsRoom(r, scene, lidar_from_board) &&
        SheetInLidarFov(r, beams, lidar_from_board) &&
        EnoughLidarHits(beams, print, lidar_from_board, plan.azimuth_offset_rad)) {
      return plan;
    }
  }
  throw std::runtime_error(
      "simulation: cannot place the board of pair " + std::to_string(pair) + " in " +
      std::to_string(kMaxTriesPerPair) +
      " tries: the whole sheet must be in the image with a 5% margin, in front of the LiDAR and "
      "inside its vertical field of view, " +
      "above the floor and hit by >= 4 rings (a Livox-class scanner: any) and >= 60 points of "
      "the " +
      LidarModelName(r.lidar) +
      "; try a larger board, a smaller max_distance_m or max_tilt_deg, or a LiDAR with more rings");
}

std::vector<PairPlan> PlanPairs(const SimOptions& r, const BeamTable& beams,
                                const BoardPrint& print, const LidarScene& scene) {
  std::vector<PairPlan> plans;
  for (int k = 0; k < r.num_pairs; ++k) plans.push_back(PlanPair(r, beams, print, scene, k));
  return plans;
}

void CheckOrThrow(const SimOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("simulation options: " + why);
}

void CreateFolder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw IoError(folder.string() + ": cannot create folder: " + error.message());
}

std::string PairId(int pair) {
  char text[16];
  std::snprintf(text, sizeof(text), "%04d", pair);
  return text;
}

}  // namespace

CameraModel DefaultSimCamera(bool fisheye) {
  CameraModel camera;
  camera.width = 1440;
  camera.height = 1080;
  camera.cx = 719.5;
  camera.cy = 539.5;
  if (fisheye) {
    camera.type = CameraModelType::kKannalaBrandt;
    camera.fx = camera.fy = 450.0;
    camera.distortion = {-0.01, 0.005, -0.002, 0.0005};
  } else {
    camera.type = CameraModelType::kPinholeRadTan;
    camera.fx = camera.fy = 1000.0;
    camera.distortion = {-0.1, 0.05, 0.0005, -0.0003, 0.0};
  }
  return camera;
}

bool SimOptions::Check(std::string* why) const {
  auto fail = [why](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (num_pairs < 1) return fail("num_pairs must be >= 1");
  if (!std::isfinite(min_distance_m) || !std::isfinite(max_distance_m) || min_distance_m <= 0.0) {
    return fail("min_distance_m must be positive and finite");
  }
  if (max_distance_m <= min_distance_m) return fail("max_distance_m must exceed min_distance_m");
  if (!(max_tilt_deg >= 0.0 && max_tilt_deg < 80.0)) return fail("max_tilt_deg must be in [0, 80)");
  if (!(lidar_frame_s >= 0.01 && lidar_frame_s <= 5.0))
    return fail("lidar_frame_s must be in [0.01, 5] s");
  if (!(lidar_range_noise_m >= 0.0) || !std::isfinite(lidar_range_noise_m)) {
    return fail("lidar_range_noise_m must be >= 0");
  }
  if (!(lidar_angular_noise_rad >= 0.0 && lidar_angular_noise_rad <= 0.02))
    return fail("lidar_angular_noise_rad must be in [0, 0.02] (about 1.1 deg)");
  if (!(std::abs(lidar_range_offset_m) <= 0.5))
    return fail("lidar_range_offset_m must be within ±0.5 m");
  if (!(image_noise >= 0.0) || !std::isfinite(image_noise)) return fail("image_noise must be >= 0");
  if (!(seed_radius_m >= 0.0) || !std::isfinite(seed_radius_m)) {
    return fail("seed_radius_m must be >= 0 (0 = automatic)");
  }
  const Mat3 rotation = cam_from_lidar.linear();
  if (!cam_from_lidar.matrix().allFinite() ||
      !(rotation.transpose() * rotation).isApprox(Mat3::Identity(), 1e-6) ||
      rotation.determinant() < 0.0) {
    return fail("cam_from_lidar must be a finite rigid transform");
  }
  std::string detail;
  if (board.cols != 0 && !board.Check(&detail)) return fail("board: " + detail);
  if (camera.width != 0 && !camera.Check(&detail)) return fail("camera: " + detail);
  return true;
}

Pose DefaultCamFromLidar() {
  // LiDAR x (forward) -> camera z, LiDAR y (left) -> camera -x, LiDAR z (up) -> camera -y.
  Mat3 axes;
  axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Mat3 mount_error = (Eigen::AngleAxisd(1.0 * kDegToRad, Vec3::UnitZ()) *
                            Eigen::AngleAxisd(-1.5 * kDegToRad, Vec3::UnitY()) *
                            Eigen::AngleAxisd(2.0 * kDegToRad, Vec3::UnitX()))
                               .toRotationMatrix();
  // The camera centre in the LiDAR frame: 8 cm forward, 5 cm left, 10 cm below.
  const Vec3 camera_in_lidar(0.08, 0.05, -0.10);
  Pose cam_from_lidar = Pose::Identity();
  cam_from_lidar.linear() = mount_error * axes;
  cam_from_lidar.translation() = -cam_from_lidar.linear() * camera_in_lidar;
  return cam_from_lidar;
}

SimOptions SimPreset(const std::string& name) {
  SimOptions options;  // camera left empty: the default pinhole, or fisheye when asked for
  options.board = BoardPreset("a3");
  if (name == "default" || name == "demo") {
    // The demo shows a well-posed session: a 128-beam LiDAR sees an A3 sheet with 10+ rings.
    options.lidar = name == "demo" ? LidarModel::kOs0_128 : LidarModel::kVlp16;
    options.num_pairs = name == "demo" ? 16 : 20;
    options.min_distance_m = name == "demo" ? 1.2 : 1.5;
    options.max_distance_m = name == "demo" ? 3.0 : 4.0;
    options.lidar_range_noise_m = 0.005;
    options.image_noise = 0.005;
    return options;
  }
  if (name == "paper") {
    // Ca²Lib Section 4.1: HDL-64, 8x6 squares of 0.2 m (7x5 inner corners) printed edge to edge.
    options.lidar = LidarModel::kHdl64;
    options.board = BoardPreset("paper");
    options.num_pairs = 53;
    options.min_distance_m = 3.0;
    options.max_distance_m = 8.0;
    options.max_tilt_deg = 45.0;
    return options;
  }
  throw std::invalid_argument("unknown simulation preset '" + name +
                              "' (known: default, paper, demo)");
}

std::vector<Pose> SampleBoardPoses(const SimOptions& options) {
  CheckOrThrow(options);
  const SimOptions r = Resolve(options);
  const BeamTable beams = SimBeamTable(r);
  const BoardPrint print(r.board);
  std::vector<Pose> poses;
  for (const PairPlan& plan : PlanPairs(r, beams, print, RoomScene(r))) {
    poses.push_back(plan.cam_from_board);
  }
  return poses;
}

SimOptions ResolveSimOptions(const SimOptions& options) { return Resolve(options); }

std::vector<SimPairTruth> SimulatePairTruth(const SimOptions& options) {
  CheckOrThrow(options);
  const SimOptions r = Resolve(options);
  const BeamTable beams = SimBeamTable(r);
  const BoardPrint print(r.board);
  const Pose lidar_from_cam = r.cam_from_lidar.inverse();
  std::vector<SimPairTruth> truth;
  for (const PairPlan& plan : PlanPairs(r, beams, print, RoomScene(r))) {
    SimPairTruth pair;
    pair.cam_from_board = plan.cam_from_board;
    const BoardReturns hits =
        ScanBoardOnly(beams, print, lidar_from_cam * plan.cam_from_board, plan.azimuth_offset_rad);
    // As the PCD file stores them: floats.
    for (const Vec3& p : hits.points)
      pair.lidar_board_points.push_back(p.cast<float>().cast<double>());
    truth.push_back(std::move(pair));
  }
  return truth;
}

Dataset SimulateDataset(const SimOptions& options, const std::filesystem::path& out_dir) {
  CheckOrThrow(options);
  const SimOptions r = Resolve(options);
  const BeamTable beams = SimBeamTable(r);
  const BoardPrint print(r.board);
  LidarScene scene = RoomScene(r);
  const std::filesystem::path root = std::filesystem::absolute(out_dir);
  CreateFolder(root / "clouds");
  CreateFolder(root / "images");

  Dataset dataset;
  dataset.manifest = root / "dataset.json";
  dataset.camera = r.camera;
  dataset.target = r.board;
  dataset.lidar_rings = beams.HasRings() ? static_cast<int>(beams.elevations_rad.size()) : 0;
  dataset.cam_from_lidar_ground_truth = r.cam_from_lidar;
  SimulationRecord record;
  record.lidar_model = LidarModelName(r.lidar);
  record.num_pairs = r.num_pairs;
  record.min_distance_m = r.min_distance_m;
  record.max_distance_m = r.max_distance_m;
  record.max_tilt_deg = r.max_tilt_deg;
  if (beams.risley) record.lidar_frame_s = r.lidar_frame_s;
  record.lidar_range_noise_m = r.lidar_range_noise_m;
  record.lidar_range_offset_m = r.lidar_range_offset_m;
  record.lidar_angular_noise_rad = r.lidar_angular_noise_rad;
  record.image_noise = r.image_noise;
  record.clutter = r.clutter;
  record.board_only_clouds = r.board_only_clouds;
  record.lidar_viewpoints = r.lidar_viewpoints;
  record.seed_radius_m = r.seed_radius_m;
  record.seed = r.seed;
  dataset.simulation = record;
  const Pose lidar_from_cam = r.cam_from_lidar.inverse();
  for (int k = 0; k < r.num_pairs; ++k) {
    const PairPlan plan = PlanPair(r, beams, print, scene, k);
    PairEntry entry;
    entry.id = PairId(k);
    entry.cloud = root / "clouds" / (entry.id + ".pcd");
    entry.image = root / "images" / (entry.id + ".png");
    scene.lidar_from_board = lidar_from_cam * plan.cam_from_board;
    if (r.lidar_seeds)
      entry.lidar_seed =
          LidarSeed{BoardHitCentroid(beams, print, scene.lidar_from_board, plan.azimuth_offset_rad),
                    r.seed_radius_m};

    LidarScanOptions scan_options;
    scan_options.range_noise_m = r.lidar_range_noise_m;
    scan_options.range_offset_m = r.lidar_range_offset_m;
    scan_options.angular_noise_rad = r.lidar_angular_noise_rad;
    scan_options.azimuth_offset_rad = plan.azimuth_offset_rad;
    scan_options.seed = MixSeed(r.seed, k, 1);
    SavePcd(entry.cloud,
            SimulateLidarScan(beams, print, scene, scan_options)
                .ToCloud(r.board_only_clouds, r.lidar_viewpoints),
            PcdEncoding::kBinary);

    RenderOptions render;
    render.image_noise = r.image_noise;
    render.seed = MixSeed(r.seed, k, 2);
    SaveImage(entry.image, RenderBoardImage(r.camera, r.board, plan.cam_from_board, render));
    dataset.pairs.push_back(entry);
  }
  SaveDataset(dataset.manifest, dataset);
  return dataset;
}

SimulatedPair SimulatePairAt(const SimOptions& resolved, const Pose& cam_from_board,
                             int pair_index) {
  CheckOrThrow(resolved);
  const SimOptions& r = resolved;
  const BeamTable beams = SimBeamTable(r);
  const BoardPrint print(r.board);
  LidarScene scene = RoomScene(r);
  std::mt19937_64 rng(MixSeed(r.seed, pair_index, 0));
  const double azimuth_offset =
      beams.PhaseSpanRad() * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  scene.lidar_from_board = r.cam_from_lidar.inverse() * cam_from_board;
  SimulatedPair pair;
  pair.seed = LidarSeed{BoardHitCentroid(beams, print, scene.lidar_from_board, azimuth_offset),
                        r.seed_radius_m};
  LidarScanOptions scan_options;
  scan_options.range_noise_m = r.lidar_range_noise_m;
  scan_options.range_offset_m = r.lidar_range_offset_m;
  scan_options.angular_noise_rad = r.lidar_angular_noise_rad;
  scan_options.azimuth_offset_rad = azimuth_offset;
  scan_options.seed = MixSeed(r.seed, pair_index, 1);
  pair.cloud = SimulateLidarScan(beams, print, scene, scan_options)
                   .ToCloud(r.board_only_clouds, r.lidar_viewpoints);
  RenderOptions render;
  render.image_noise = r.image_noise;
  render.seed = MixSeed(r.seed, pair_index, 2);
  pair.image = RenderBoardImage(r.camera, r.board, cam_from_board, render);
  return pair;
}

bool PlaceableInSimulation(const SimOptions& resolved, const Pose& cam_from_board,
                           std::string* why) {
  const SimOptions& r = resolved;
  const BeamTable beams = SimBeamTable(r);
  const BoardPrint print(r.board);
  const LidarScene scene = RoomScene(r);
  const Pose lidar_from_board = r.cam_from_lidar.inverse() * cam_from_board;
  auto fail = [&](const char* reason) {
    if (why) *why = reason;
    return false;
  };
  if (!SheetInImage(r, cam_from_board)) return fail("the sheet leaves the image");
  if (!SheetFitsRoom(r, scene, lidar_from_board)) return fail("the sheet does not fit the room");
  if (!SheetInLidarFov(r, beams, lidar_from_board))
    return fail("the sheet leaves the LiDAR's vertical field of view");
  if (!EnoughLidarHits(beams, print, lidar_from_board, 0.0))
    return fail("too few LiDAR rings or points on the sheet");
  return true;
}

bool FitsInSimulatedRoom(const SimOptions& resolved, const Pose& cam_from_board) {
  return SheetFitsRoom(resolved, RoomScene(resolved),
                       resolved.cam_from_lidar.inverse() * cam_from_board);
}

Pose RandomPlacement(const SimOptions& resolved, int pair_index) {
  const BeamTable beams = SimBeamTable(resolved);
  const BoardPrint print(resolved.board);
  return PlanPair(resolved, beams, print, RoomScene(resolved), pair_index).cam_from_board;
}

}  // namespace calibench
