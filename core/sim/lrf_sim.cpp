#include "core/sim/lrf_sim.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>

#include "core/geometry/geometry.h"

namespace calibench {
namespace fs = std::filesystem;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Validity of a sampled pose: the scan needs a few points on each segment E…F, F…G, G…H, H…I to
// fit its lines (paper Fig. 6), and the depth camera a few hundred pixels per face to fit planes
// (Fig. 7). Corners F, G, H stay in the inner 80 % of AB, AC, AD so that the faces do not thin out
// to a few points, and faces are not seen more obliquely than 75 degrees.
constexpr int kMinScanPointsPerSegment = 20;
constexpr int kMinPixelsPerFace = 400;
constexpr double kSegmentMargin = 0.1;
constexpr double kMinViewCosine = 0.26;

bool Fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

// Surfaces of the scene. 0..2 are the target faces of lrf_types.h.
enum Surface : int {
  kNone = -1,
  kBase = 0,
  kAbc = 1,
  kAcd = 2,
  kTentEnd = 3,  // the vertical triangle BCD closing the tent at its foot
  kClutter = 4,  // walls and floor
};

// Portable random numbers: the same bytes for a seed on every standard library (std::*
// distributions are implementation-defined).
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Gaussian() {  // Box–Muller, both values used
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(1.0 - Uniform())),
                 angle = 2.0 * M_PI * Uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

uint64_t MixSeed(uint64_t seed, uint64_t stream) {  // SplitMix64 finaliser
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

struct Hit {
  double t = kInf;  // metres along the unit ray
  int surface = kNone;
};

// Möller–Trumbore; keeps the nearer hit.
void CastTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                  int surface, Hit* hit) {
  const Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-15) return;
  const Vec3 s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return;
  const double t = e2.dot(q) / det;
  if (t > 1e-9 && t < hit->t) *hit = Hit{t, surface};
}

void CastPlane(const Vec3& o, const Vec3& d, const Plane& plane, int surface, Hit* hit) {
  const double along = plane.normal.dot(d);
  if (std::abs(along) < 1e-15) return;
  const double t = -plane.SignedDistance(o) / along;
  if (t > 1e-9 && t < hit->t) *hit = Hit{t, surface};
}

// Walls and floor in the (left) camera frame, placed from the distance range so that the target
// always stands in front of them: a back wall, a wall on the left, a floor below.
std::vector<Plane> ClutterPlanes(const LrfSimOptions& options) {
  if (!options.clutter) return {};
  const double far = options.target_distance_max_m;
  // Normals towards the camera: the scene lies on their positive side.
  return {Plane{-Vec3::UnitZ(), far + 1.5}, Plane{Vec3::UnitX(), 0.5 * far + 1.0},
          Plane{-Vec3::UnitY(), 0.8 + 0.1 * far}};
}

// The scene for one target pose, ray-cast in the left camera frame (nearest hit wins, so the tent
// hides the base behind it).
class Scene {
 public:
  Scene(const LrfSimOptions& options, const Pose& cam_from_target)
      : target_(options.target),
        target_from_cam_(cam_from_target.inverse()),
        clutter_(ClutterPlanes(options)) {
    const ThreeFaceTarget& t = options.target;
    bound_centre_ = cam_from_target * Vec3(0.0, 0.0, 0.5 * t.ridge_height);
    bound_radius_ = 0.5 * Vec3(t.base_width, t.base_height, t.ridge_height).norm() + 1e-6;
  }

  Hit Cast(const Vec3& origin_cam, const Vec3& direction_cam) const {
    Hit hit;
    for (const Plane& plane : clutter_) CastPlane(origin_cam, direction_cam, plane, kClutter, &hit);
    // Most depth pixels miss the target: a bounding sphere test first.
    const Vec3 to_centre = bound_centre_ - origin_cam;
    const double along = to_centre.dot(direction_cam);
    if (to_centre.squaredNorm() - along * along > bound_radius_ * bound_radius_) return hit;
    const Vec3 o = target_from_cam_ * origin_cam;
    const Vec3 d = target_from_cam_.linear() * direction_cam;
    const Vec3 a = target_.A(), b = target_.B(), c = target_.C(), e = target_.D();
    CastTriangle(o, d, a, b, c, kAbc, &hit);
    CastTriangle(o, d, a, c, e, kAcd, &hit);
    CastTriangle(o, d, b, e, c, kTentEnd, &hit);
    if (std::abs(d.z()) > 1e-15) {
      const double t = -o.z() / d.z();
      const Vec3 p = o + t * d;
      if (t > 1e-9 && t < hit.t && std::abs(p.x()) <= 0.5 * target_.base_width &&
          std::abs(p.y()) <= 0.5 * target_.base_height)
        hit = Hit{t, kBase};
    }
    return hit;
  }
  // Target-frame point of a hit, to tell the base's left margin from its right one.
  Vec3 InTarget(const Vec3& origin_cam, const Vec3& direction_cam, double t) const {
    return target_from_cam_ * (origin_cam + t * direction_cam);
  }

 private:
  ThreeFaceTarget target_;
  Pose target_from_cam_;
  std::vector<Plane> clutter_;
  Vec3 bound_centre_;  // camera frame
  double bound_radius_ = 0.0;
};

int RayCount(const LrfSensorSpec& lrf) {
  // A full turn must not repeat its first ray at +180 degrees.
  if (lrf.fov_deg >= 360.0 - 1e-9)
    return static_cast<int>(std::ceil(360.0 / lrf.angular_step_deg - 1e-9));
  return static_cast<int>(std::floor(lrf.fov_deg / lrf.angular_step_deg + 1e-9)) + 1;
}

// The scan (range noise when rng is given); `surfaces` receives the hit surface per ray and
// `target_x` the target-frame x of each hit (NaN for none).
LaserScan RenderScan(const LrfSimOptions& options, const Scene& scene, Rng* rng,
                     std::vector<int>* surfaces = nullptr,
                     std::vector<double>* target_x = nullptr) {
  const LrfSensorSpec& lrf = options.lrf;
  LaserScan scan;
  scan.angle_min = -0.5 * lrf.fov_deg * kDegToRad;
  scan.angle_increment = lrf.angular_step_deg * kDegToRad;
  scan.range_min = lrf.range_min_m;
  scan.range_max = lrf.range_max_m;
  const size_t count = RayCount(lrf);
  scan.ranges.assign(count, std::numeric_limits<double>::quiet_NaN());
  if (surfaces) surfaces->assign(count, kNone);
  if (target_x) target_x->assign(count, std::numeric_limits<double>::quiet_NaN());
  const Vec3 origin = options.cam_from_lrf.translation();
  for (size_t i = 0; i < count; ++i) {
    const double angle = scan.Angle(i);
    const Vec3 direction =
        options.cam_from_lrf.linear() * Vec3(std::cos(angle), std::sin(angle), 0.0);
    const Hit hit = scene.Cast(origin, direction);
    if (hit.surface == kNone) continue;
    const double range = hit.t + (rng ? lrf.range_noise_m * rng->Gaussian() : 0.0);
    if (range < lrf.range_min_m || range > lrf.range_max_m) continue;
    scan.ranges[i] = range;
    if (surfaces) (*surfaces)[i] = hit.surface;
    if (target_x) (*target_x)[i] = scene.InTarget(origin, direction, hit.t).x();
  }
  return scan;
}

// Unit ray of pixel (u, v) in its own camera frame.
Vec3 PixelRay(const DepthIntrinsics& in, int u, int v) {
  return in.Unproject(Vec2(static_cast<double>(u), static_cast<double>(v)), 1.0).normalized();
}

// Depth image of a camera at left_from_camera; noise σ_z = z² σ_disp / (f b) (paper Eq. (3):
// z = f b / d, so dz/dd = -z² / (f b)).
DepthImage RenderDepth(const LrfSimOptions& options, const Scene& scene,
                       const Pose& left_from_camera, Rng* rng) {
  const DepthCameraSpec& spec = options.depth;
  const DepthIntrinsics& in = spec.intrinsics;
  DepthImage depth;
  depth.intrinsics = in;
  depth.depth_m.assign(static_cast<size_t>(in.width) * in.height, 0.0f);
  const double noise_per_z2 = spec.disparity_noise_px / (in.fx * spec.stereo_baseline_m);
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const Vec3 ray = PixelRay(in, u, v);
      const Hit hit = scene.Cast(left_from_camera.translation(), left_from_camera.linear() * ray);
      if (hit.surface == kNone) continue;
      double z = hit.t * ray.z();
      if (z > spec.max_depth_m) continue;
      if (rng) z += z * z * noise_per_z2 * rng->Gaussian();
      if (z > 0) depth.depth_m[static_cast<size_t>(v) * in.width + u] = static_cast<float>(z);
    }
  }
  return depth;
}

Pose RightFromLeft(const LrfSimOptions& options) {
  Pose right_from_left = Pose::Identity();
  right_from_left.translation() = Vec3(-options.stereo_right_baseline_m, 0.0, 0.0);
  return right_from_left;
}

// A candidate pose: facing the camera along its viewing ray, upright, then yawed and tilted, and
// lifted so that the scan plane crosses the ridge AC at a random height in its middle third.
std::optional<Pose> DrawCandidate(const LrfSimOptions& options, Rng& rng) {
  const ThreeFaceTarget& target = options.target;
  const DepthIntrinsics& in = options.depth.intrinsics;
  const double distance = rng.Uniform(options.target_distance_min_m, options.target_distance_max_m);
  const double yaw = rng.Uniform(-1, 1) * options.target_max_yaw_deg * kDegToRad;
  const double tilt = rng.Uniform(-1, 1) * options.target_max_tilt_deg * kDegToRad;
  const double tent = target.apex_y - target.foot_y;
  const double ridge_y = rng.Uniform(target.foot_y + tent / 3, target.apex_y - tent / 3);
  const double half_fov = std::atan(std::min(in.cx, in.width - in.cx) / in.fx);
  const double bearing = rng.Uniform(-0.5, 0.5) * half_fov;
  Pose cam_from_target = Pose::Identity();
  // Target z towards the camera, y up (camera -y), x = camera x.
  cam_from_target.linear() = Eigen::AngleAxisd(bearing, Vec3::UnitY()).toRotationMatrix() *
                             Vec3(1, -1, -1).asDiagonal() *
                             Eigen::AngleAxisd(yaw, Vec3::UnitY()).toRotationMatrix() *
                             Eigen::AngleAxisd(tilt, Vec3::UnitX()).toRotationMatrix();
  const Plane scan_plane = TransformPlane(options.cam_from_lrf, Plane{Vec3::UnitZ(), 0.0});
  if (std::abs(scan_plane.normal.y()) < 0.2) return std::nullopt;  // scan plane far from level
  const Vec3 on_ridge(0.0, ridge_y, target.ridge_height * (target.apex_y - ridge_y) / tent);
  Vec3 centre(distance * std::sin(bearing), 0.0, distance * std::cos(bearing));
  centre.y() = -(scan_plane.distance + scan_plane.normal.dot(cam_from_target.linear() * on_ridge) +
                 scan_plane.normal.x() * centre.x() + scan_plane.normal.z() * centre.z()) /
               scan_plane.normal.y();
  cam_from_target.translation() = centre;
  return cam_from_target;
}

// Geometry-only checks: target in view and in front of the clutter, the scan plane crossing AB,
// AC, AD inside the segments and both base margins, both sensors in front of all three faces.
bool GeometryValid(const LrfSimOptions& options, const Pose& cam_from_target) {
  const ThreeFaceTarget& target = options.target;
  const DepthIntrinsics& in = options.depth.intrinsics;
  const double hw = 0.5 * target.base_width, hh = 0.5 * target.base_height;
  const Vec3 corners[] = {Vec3(-hw, -hh, 0), Vec3(hw, -hh, 0), Vec3(hw, hh, 0),
                          Vec3(-hw, hh, 0),  target.C(),       target.A()};
  const std::vector<Plane> clutter = ClutterPlanes(options);
  for (const Vec3& corner : corners) {
    const Vec3 p = cam_from_target * corner;
    if (p.z() < 0.2 || p.z() > options.depth.max_depth_m) return false;
    const Vec2 pixel = *in.Project(p);  // z > 0 here
    if (pixel.x() < 2 || pixel.y() < 2 || pixel.x() > in.width - 3 || pixel.y() > in.height - 3)
      return false;
    for (const Plane& plane : clutter)
      if (plane.SignedDistance(p) < 0.05) return false;
  }
  const Pose target_from_lrf = cam_from_target.inverse() * options.cam_from_lrf;
  const Plane scan = TransformPlane(target_from_lrf, Plane{Vec3::UnitZ(), 0.0});
  for (const Vec3& foot : {target.B(), target.C(), target.D()}) {
    const double along = scan.normal.dot(foot - target.A());
    if (std::abs(along) < 1e-12) return false;
    const double u = -scan.SignedDistance(target.A()) / along;
    if (u < kSegmentMargin || u > 1 - kSegmentMargin) return false;
  }
  if (std::abs(scan.normal.y()) < 1e-6) return false;
  for (const double x : {-hw, hw}) {
    const double y = -(scan.distance + scan.normal.x() * x) / scan.normal.y();
    if (std::abs(y) > hh - 0.02) return false;
  }
  const Vec3 camera_in_target = cam_from_target.inverse().translation();
  const Vec3 lrf_in_target = target_from_lrf.translation();
  const auto planes = target.FacePlanes();
  const Vec3 face_points[] = {Vec3::Zero(), target.A(), target.A()};
  for (int f = 0; f < 3; ++f) {
    for (const Vec3& sensor : {camera_in_target, lrf_in_target}) {
      const Vec3 to_sensor = (sensor - face_points[f]).normalized();
      if (planes[f].normal.dot(to_sensor) < kMinViewCosine) return false;
    }
  }
  return true;
}

// Rendered checks: enough scan points on E…F, F…G, G…H, H…I and enough pixels per face.
bool CoverageValid(const LrfSimOptions& options, const Pose& cam_from_target) {
  const Scene scene(options, cam_from_target);
  std::vector<int> surfaces;
  std::vector<double> target_x;
  RenderScan(options, scene, nullptr, &surfaces, &target_x);
  int counts[4] = {0, 0, 0, 0};  // base left, ABC, ACD, base right
  for (size_t i = 0; i < surfaces.size(); ++i) {
    if (surfaces[i] == kBase) ++counts[target_x[i] < 0 ? 0 : 3];
    if (surfaces[i] == kAbc || surfaces[i] == kAcd) ++counts[surfaces[i]];
  }
  if (*std::min_element(counts, counts + 4) < kMinScanPointsPerSegment) return false;
  // Pixels, only inside the target's bounding box (GeometryValid put it fully in view).
  const DepthIntrinsics& in = options.depth.intrinsics;
  const ThreeFaceTarget& target = options.target;
  const double hw = 0.5 * target.base_width, hh = 0.5 * target.base_height;
  double u_min = in.width, u_max = 0, v_min = in.height, v_max = 0;
  for (const Vec3& corner :
       {Vec3(-hw, -hh, 0), Vec3(hw, -hh, 0), Vec3(hw, hh, 0), Vec3(-hw, hh, 0), target.C()}) {
    const auto pixel = in.Project(cam_from_target * corner);
    if (!pixel) return false;  // GeometryValid put the target in front; never here
    u_min = std::min(u_min, pixel->x()), u_max = std::max(u_max, pixel->x());
    v_min = std::min(v_min, pixel->y()), v_max = std::max(v_max, pixel->y());
  }
  int pixels[3] = {0, 0, 0};
  for (int v = std::max(0, int(v_min)); v <= std::min(in.height - 1, int(v_max) + 1); ++v) {
    for (int u = std::max(0, int(u_min)); u <= std::min(in.width - 1, int(u_max) + 1); ++u) {
      const Hit hit = scene.Cast(Vec3::Zero(), PixelRay(in, u, v));
      if (hit.surface >= kBase && hit.surface <= kAcd) ++pixels[hit.surface];
    }
  }
  return *std::min_element(pixels, pixels + 3) >= kMinPixelsPerFace;
}

}  // namespace

bool LrfSensorSpec::Check(std::string* why) const {
  if (!(fov_deg > 0 && fov_deg <= 360)) return Fail(why, "LRF fov_deg must be in (0, 360]");
  if (!(angular_step_deg > 0 && angular_step_deg <= fov_deg))
    return Fail(why, "LRF angular_step_deg must be > 0 and <= fov_deg");
  if (!(range_noise_m >= 0 && std::isfinite(range_noise_m)))
    return Fail(why, "LRF range_noise_m must be finite and >= 0");
  if (!(range_min_m >= 0 && range_min_m < range_max_m && std::isfinite(range_max_m)))
    return Fail(why, "LRF ranges must satisfy 0 <= range_min_m < range_max_m (finite)");
  return true;
}

bool DepthCameraSpec::Check(std::string* why) const {
  if (!intrinsics.Check(why)) return false;
  if (!(stereo_baseline_m > 0)) return Fail(why, "depth stereo_baseline_m must be > 0");
  if (!(disparity_noise_px >= 0 && std::isfinite(disparity_noise_px)))
    return Fail(why, "depth disparity_noise_px must be finite and >= 0");
  if (!(max_depth_m > 0)) return Fail(why, "depth max_depth_m must be > 0");
  return true;
}

bool LrfSimOptions::Check(std::string* why) const {
  if (observations < 1) return Fail(why, "observations must be >= 1");
  if (!lrf.Check(why) || !depth.Check(why) || !target.Check(why)) return false;
  const Mat3 rotation = cam_from_lrf.linear();
  if (!cam_from_lrf.matrix().allFinite() ||
      (rotation * rotation.transpose() - Mat3::Identity()).norm() > 1e-6 ||
      rotation.determinant() < 0)
    return Fail(why, "cam_from_lrf must be a rigid transform");
  if (!(target_distance_min_m > 0 && target_distance_min_m <= target_distance_max_m))
    return Fail(why, "target distances must satisfy 0 < min <= max (metres)");
  if (!(target_max_yaw_deg >= 0 && target_max_yaw_deg < 75))
    return Fail(why, "target_max_yaw_deg must be in [0, 75)");
  if (!(target_max_tilt_deg >= 0 && target_max_tilt_deg < 45))
    return Fail(why, "target_max_tilt_deg must be in [0, 45)");
  if (stereo && !(stereo_right_baseline_m > 0))
    return Fail(why, "stereo_right_baseline_m must be > 0");
  return true;
}

Pose DefaultCamFromLrf() {
  Mat3 axes;  // columns: LRF x -> camera z, LRF y -> -x, LRF z -> -y
  axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Pose cam_from_lrf = Pose::Identity();
  // Roll 1.5°, pitch -2°, yaw 1° about the LRF's own axes: "level to within a few degrees".
  cam_from_lrf.linear() = axes * ExpSO3(Vec3(1.5, -2.0, 1.0) * kDegToRad);
  cam_from_lrf.translation() = Vec3(0.0, -0.15, -0.10);  // LRF origin: 0.15 m up, 0.10 m back
  return cam_from_lrf;
}

std::optional<LrfSimOptions> LrfSimPreset(const std::string& name) {
  LrfSimOptions options;
  if (name == "paper") return options;
  if (name == "ideal") {
    options.lrf.range_noise_m = 0.0;
    options.depth.disparity_noise_px = 0.0;
    return options;
  }
  return std::nullopt;
}

std::vector<Pose> SampleTargetPoses(const LrfSimOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("LRF simulator options: " + why);
  Rng rng(MixSeed(options.seed, 0));
  std::vector<Pose> poses;
  // Fewer poses than asked only when the options leave (almost) no valid placement.
  const int max_attempts = 500 * options.observations;
  for (int attempt = 0; attempt < max_attempts && int(poses.size()) < options.observations;
       ++attempt) {
    const std::optional<Pose> candidate = DrawCandidate(options, rng);
    if (candidate && GeometryValid(options, *candidate) && CoverageValid(options, *candidate))
      poses.push_back(*candidate);
  }
  return poses;
}

LrfSimObservation RenderLrfObservation(const LrfSimOptions& options, const Pose& cam_from_target,
                                       uint64_t noise_seed) {
  const Scene scene(options, cam_from_target);
  Rng rng(noise_seed);
  LrfSimObservation observation;
  observation.cam_from_target = cam_from_target;
  observation.scan = RenderScan(options, scene, &rng);
  observation.depth = RenderDepth(options, scene, Pose::Identity(), &rng);
  if (options.stereo)
    observation.depth_right = RenderDepth(options, scene, RightFromLeft(options).inverse(), &rng);
  return observation;
}

fs::path WriteLrfSimDataset(const LrfSimOptions& options, const fs::path& out_dir) {
  const std::vector<Pose> poses = SampleTargetPoses(options);
  if (static_cast<int>(poses.size()) < options.observations)
    throw std::invalid_argument("LRF simulator: found only " + std::to_string(poses.size()) +
                                " of " + std::to_string(options.observations) +
                                " valid target poses; widen the distance range or the camera's "
                                "field of view, or use a smaller target");
  const fs::path root = fs::absolute(out_dir);
  for (const char* sub : {"scans", "depth", "depth_right"}) {
    if (std::string(sub) == "depth_right" && !options.stereo) continue;
    std::error_code ec;
    fs::create_directories(root / sub, ec);
    if (ec) throw IoError((root / sub).string() + ": cannot create the folder: " + ec.message());
  }
  LrfDataset left;
  left.target_type = LrfTargetType::kThreeFace;
  left.three_face = options.target;
  left.depth_camera = options.depth.intrinsics;
  left.cam_from_lrf_ground_truth = options.cam_from_lrf;
  LrfDataset right = left;
  if (options.stereo) {
    left.right_from_left = right.right_from_left = RightFromLeft(options);
    right.cam_from_lrf_ground_truth = RightFromLeft(options) * options.cam_from_lrf;
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    char id[32];
    std::snprintf(id, sizeof(id), "%04zu", i);
    const LrfSimObservation observation =
        RenderLrfObservation(options, poses[i], MixSeed(options.seed, i + 1));
    LrfPairEntry pair;
    pair.id = id;
    pair.scan = root / "scans" / (pair.id + ".json");
    pair.depth = root / "depth" / (pair.id + ".png");
    SaveLaserScanJson(pair.scan, observation.scan);
    SaveDepthPng(pair.depth, observation.depth);
    left.pairs.push_back(pair);
    if (options.stereo) {
      pair.depth = root / "depth_right" / (pair.id + ".png");
      SaveDepthPng(pair.depth, observation.depth_right);
      right.pairs.push_back(pair);
    }
  }
  SaveLrfDataset(root / "manifest.json", left);
  if (options.stereo) SaveLrfDataset(root / "right.json", right);
  return root / "manifest.json";
}

}  // namespace calibench
