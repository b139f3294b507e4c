#include "core/sim/textured_scene.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "core/base/parallel.h"

namespace calibench {
namespace {

constexpr double kAmbientLight = 0.35;  // of the light a face gets whatever its orientation
constexpr double kNoSurfaceGrey = 0.4;  // where a pixel's ray leaves the room (never, closed)
constexpr double kReflectivityScale = 230.0;
constexpr double kReflectivityNoise = 2.0;  // 0..255
constexpr double kPaintStepM = 0.002;  // each painted layer this much off what it is painted on

// A quad ready for ray tests.
struct QuadGeometry {
  Vec3 centre, normal, axis_u, axis_v;
  Vec2 half_size;
  double albedo;
};

std::vector<QuadGeometry> Geometry(const TexturedScene& scene) {
  std::vector<QuadGeometry> quads;
  quads.reserve(scene.quads.size());
  for (const TexturedQuad& q : scene.quads) {
    const Mat3 r = q.world_from_quad.linear();
    quads.push_back(
        {q.world_from_quad.translation(), r.col(2), r.col(0), r.col(1), q.half_size_m, q.albedo});
  }
  return quads;
}

struct Hit {
  double range = 0.0;
  const QuadGeometry* quad = nullptr;
};

// The nearest quad along origin + s·dir with s in (min_range, max_range).
std::optional<Hit> CastRay(const std::vector<QuadGeometry>& quads, const Vec3& origin,
                           const Vec3& dir, double min_range, double max_range) {
  Hit best{max_range, nullptr};
  for (const QuadGeometry& q : quads) {
    const double denom = q.normal.dot(dir);
    if (std::abs(denom) < 1e-12) continue;
    const double s = q.normal.dot(q.centre - origin) / denom;
    if (s <= min_range || s >= best.range) continue;
    const Vec3 local = origin + s * dir - q.centre;
    if (std::abs(local.dot(q.axis_u)) > q.half_size.x() ||
        std::abs(local.dot(q.axis_v)) > q.half_size.y())
      continue;
    best = {s, &q};
  }
  if (!best.quad) return std::nullopt;
  return best;
}

// A frame whose z (the quad's normal) is `normal`, x is `axis_u`, centred at `centre`.
Pose QuadPose(const Vec3& centre, const Vec3& axis_u, const Vec3& normal) {
  Pose pose = Pose::Identity();
  const Vec3 z = normal.normalized(), x = axis_u.normalized();
  pose.linear().col(0) = x;
  pose.linear().col(1) = z.cross(x);
  pose.linear().col(2) = z;
  pose.translation() = centre;
  return pose;
}

// Dark or bright paint, so that a poster stands out from the wall it is on.
double ContrastingAlbedo(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> dark(0.04, 0.22), bright(0.82, 0.97);
  std::bernoulli_distribution pick_dark(0.55);
  return pick_dark(rng) ? dark(rng) : bright(rng);
}

struct Wall {
  Vec3 centre, axis_u, inward;
  Vec2 half_size;
};

void AddBox(const Vec3& foot_centre, double yaw, const Vec3& size, double albedo, bool top,
            TexturedScene* scene) {
  const Vec3 ax(std::cos(yaw), std::sin(yaw), 0.0), ay(-std::sin(yaw), std::cos(yaw), 0.0);
  const Vec3 up = Vec3::UnitZ();
  const Vec3 mid = foot_centre + 0.5 * size.z() * up;
  for (int side = 0; side < 4; ++side) {
    const Vec3 out = side == 0 ? ax : side == 1 ? -ax : side == 2 ? ay : -ay;
    const Vec3 along = side < 2 ? ay : ax;
    const double half_out = side < 2 ? size.x() / 2 : size.y() / 2;
    const double half_along = side < 2 ? size.y() / 2 : size.x() / 2;
    scene->quads.push_back(
        {QuadPose(mid + half_out * out, along, out), Vec2(half_along, size.z() / 2), albedo});
  }
  if (top)
    scene->quads.push_back(
        {QuadPose(foot_centre + size.z() * up, ax, up), Vec2(size.x() / 2, size.y() / 2), albedo});
}

}  // namespace

bool TexturedRoomOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(half_length_m >= 3.0 && half_width_m >= 3.0))
    return fail("the room must be at least 6 m × 6 m (half sizes >= 3 m)");
  if (!(height_m >= 2.0)) return fail("the room must be at least 2 m high");
  if (boxes < 0 || posters < 0 || floor_marks < 0) return fail("counts must be >= 0");
  return true;
}

TexturedScene MakeTexturedRoom(const TexturedRoomOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("textured room: " + why);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double a, double b) { return a + (b - a) * unit(rng); };
  const double L = options.half_length_m, W = options.half_width_m, H = options.height_m;
  TexturedScene scene;
  scene.quads.push_back({QuadPose(Vec3(0, 0, 0), Vec3::UnitX(), Vec3::UnitZ()), Vec2(L, W), 0.33});
  scene.quads.push_back({QuadPose(Vec3(0, 0, H), Vec3::UnitX(), -Vec3::UnitZ()), Vec2(L, W), 0.85});
  const std::vector<Wall> walls = {
      {Vec3(L, 0, H / 2), Vec3::UnitY(), -Vec3::UnitX(), Vec2(W, H / 2)},
      {Vec3(-L, 0, H / 2), Vec3::UnitY(), Vec3::UnitX(), Vec2(W, H / 2)},
      {Vec3(0, W, H / 2), Vec3::UnitX(), -Vec3::UnitY(), Vec2(L, H / 2)},
      {Vec3(0, -W, H / 2), Vec3::UnitX(), Vec3::UnitY(), Vec2(L, H / 2)}};
  for (const Wall& wall : walls)
    scene.quads.push_back(
        {QuadPose(wall.centre, wall.axis_u, wall.inward), wall.half_size, uniform(0.5, 0.72)});
  // Posters: a wall in proportion to its length, a place on it, each layer a step off the last.
  for (int i = 0; i < options.posters; ++i) {
    const Wall& wall = walls[unit(rng) < L / (L + W) ? 2 + (unit(rng) < 0.5) : (unit(rng) < 0.5)];
    const Vec2 half(uniform(0.1, 0.7), uniform(0.1, 0.75));
    const double u = uniform(-wall.half_size.x() + half.x(), wall.half_size.x() - half.x());
    const double v = uniform(-wall.half_size.y() + half.y(), wall.half_size.y() - half.y());
    const Vec3 up = Vec3::UnitZ();
    const Vec3 centre =
        wall.centre + u * wall.axis_u + v * up + (i + 1) * kPaintStepM * wall.inward;
    scene.quads.push_back(
        {QuadPose(centre, wall.axis_u, wall.inward), half, ContrastingAlbedo(rng)});
  }
  for (int i = 0; i < options.floor_marks; ++i) {
    const double yaw = uniform(0, M_PI);
    const Vec2 half(uniform(0.05, 0.4), uniform(0.3, 1.2));
    const Vec3 centre(uniform(-L + 1.3, L - 1.3), uniform(-W + 1.3, W - 1.3),
                      (i + 1) * kPaintStepM);
    scene.quads.push_back({QuadPose(centre, Vec3(std::cos(yaw), std::sin(yaw), 0), Vec3::UnitZ()),
                           half, ContrastingAlbedo(rng)});
  }
  // Boxes and pillars away from the rig's path (x in [-2.5, 2.5] on y = 0), inside the walls.
  for (int i = 0, tries = 0; i < options.boxes && tries < 1000; ++tries) {
    const bool pillar = i % 4 == 3;
    const Vec3 size = pillar ? Vec3(uniform(0.3, 0.5), uniform(0.3, 0.5), H)
                             : Vec3(uniform(0.4, 1.4), uniform(0.4, 1.4), uniform(0.4, 2.0));
    const double reach = 0.75 * std::max(size.x(), size.y());
    const Vec3 foot(uniform(-L + reach + 0.2, L - reach - 0.2),
                    uniform(-W + reach + 0.2, W - reach - 0.2), 0.0);
    const double path_distance =
        std::hypot(std::max(0.0, std::abs(foot.x()) - 2.5), std::abs(foot.y()));
    if (path_distance < 1.5 + reach) continue;
    AddBox(foot, uniform(0, M_PI), size, uniform(0.12, 0.9), !pillar, &scene);
    ++i;
  }
  return scene;
}

ImageU8 RenderSceneImage(const CameraModel& camera, const Pose& world_from_cam,
                         const TexturedScene& scene, const SceneImageOptions& options) {
  CALIBENCH_CHECK(options.supersampling >= 1 && camera.width > 0 && camera.height > 0);
  const std::vector<QuadGeometry> quads = Geometry(scene);
  const Mat3 rotation = world_from_cam.linear();
  const Vec3 origin = world_from_cam.translation();
  const int ss = options.supersampling;
  std::vector<double> grey(static_cast<size_t>(camera.width) * camera.height);
  ParallelFor(static_cast<size_t>(camera.height),
              options.threads > 0 ? options.threads : DefaultThreads(), [&](size_t row) {
                for (int x = 0; x < camera.width; ++x) {
                  double sum = 0.0;
                  for (int sy = 0; sy < ss; ++sy)
                    for (int sx = 0; sx < ss; ++sx) {
                      const Vec2 pixel(x + (sx + 0.5) / ss - 0.5, row + (sy + 0.5) / ss - 0.5);
                      const std::optional<Vec3> bearing = camera.Unproject(pixel);
                      std::optional<Hit> hit;
                      if (bearing) hit = CastRay(quads, origin, rotation * *bearing, 0.0, 1e3);
                      sum += hit ? hit->quad->albedo *
                                       (kAmbientLight +
                                        (1.0 - kAmbientLight) *
                                            std::abs(hit->quad->normal.dot(scene.light_direction)))
                                 : kNoSurfaceGrey;
                    }
                  grey[row * camera.width + x] = sum / (ss * ss);
                }
              });
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.image_noise > 0 ? options.image_noise : 1.0);
  ImageU8 image;
  image.width = camera.width;
  image.height = camera.height;
  image.channels = 1;
  image.data.resize(grey.size());
  for (size_t i = 0; i < grey.size(); ++i) {
    const double value = grey[i] + (options.image_noise > 0 ? noise(rng) : 0.0);
    image.data[i] = static_cast<std::uint8_t>(std::clamp(std::lround(255.0 * value), 0L, 255L));
  }
  return image;
}

namespace {

// Casts each ray (LiDAR frame) and keeps the returns in [min, max] range, noise along the ray.
class SceneScanner {
 public:
  SceneScanner(const Pose& world_from_lidar, const TexturedScene& scene,
               const SceneScanOptions& options)
      : world_from_lidar_(world_from_lidar),
        quads_(Geometry(scene)),
        options_(options),
        rng_(options.seed) {}

  void Fire(const Vec3& origin, const Vec3& dir, double min_range, double max_range, int ring) {
    const std::optional<Hit> hit = CastRay(quads_, world_from_lidar_ * origin,
                                           world_from_lidar_.linear() * dir, min_range, max_range);
    if (!hit) return;
    double range = hit->range;
    if (options_.range_noise_m > 0) range += options_.range_noise_m * normal_(rng_);
    const double intensity =
        hit->quad->albedo * kReflectivityScale + kReflectivityNoise * normal_(rng_);
    cloud_.points.push_back((origin + range * dir).cast<float>());
    cloud_.intensity.push_back(static_cast<float>(std::clamp(intensity, 0.0, 255.0)));
    if (ring >= 0) cloud_.ring.push_back(ring);
  }

  LidarCloud Take() {
    cloud_.width = static_cast<int>(cloud_.size());
    cloud_.height = 1;
    return std::move(cloud_);
  }

 private:
  Pose world_from_lidar_;
  std::vector<QuadGeometry> quads_;
  SceneScanOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  LidarCloud cloud_;
};

}  // namespace

LidarCloud ScanSceneWithBeams(const BeamTable& beams, const Pose& world_from_lidar,
                              const TexturedScene& scene, const SceneScanOptions& options) {
  CALIBENCH_CHECK(beams.azimuth_steps > 0 && !beams.elevations_rad.empty());
  SceneScanner scanner(world_from_lidar, scene, options);
  const int rings = static_cast<int>(beams.elevations_rad.size());
  for (int step = 0; step < beams.azimuth_steps; ++step) {
    const double azimuth = options.azimuth_offset_rad + 2.0 * M_PI * step / beams.azimuth_steps;
    const double c = std::cos(azimuth), s = std::sin(azimuth);
    const Vec3& m = beams.mirror_offset_m;
    const Vec3 origin(c * m.x() - s * m.y(), s * m.x() + c * m.y(), m.z());
    for (int r = 0; r < rings; ++r) {
      const double el = beams.elevations_rad[r];
      scanner.Fire(origin, Vec3(std::cos(el) * c, std::cos(el) * s, std::sin(el)), 0.3,
                   beams.max_range_m, beams.swept ? -1 : r);
    }
  }
  return scanner.Take();
}

LidarCloud ScanSceneWithRisley(const RisleyPattern& pattern, const Pose& world_from_lidar,
                               const TexturedScene& scene, const SceneScanOptions& options) {
  SceneScanner scanner(world_from_lidar, scene, options);
  const RisleyRays rays = FireRisleyPattern(pattern, options.start_s, options.duration_s);
  for (const Vec3& dir : rays.directions)
    scanner.Fire(Vec3::Zero(), dir, pattern.min_range_m, pattern.max_range_m, -1);
  return scanner.Take();
}

}  // namespace calibench
