// A textured scene both sensors see, for the targetless check (docs/targetless.md "Simulation"):
// a room of flat rectangles — floor, walls, ceiling, boxes and pillars at several depths — and
// painted rectangles on them (posters, doors, tape) whose albedo the camera sees as grey and the
// LiDAR as reflectivity. Depth edges come from the boxes' silhouettes, painted edges from the
// posters; shading differs between faces, so the image also holds edges the LiDAR cannot see
// (as a real room does). World frame: z up, floor at z = 0, the room centred on the origin.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/lidar/cloud.h"
#include "core/lidar/risley_pattern.h"
#include "core/sim/sim.h"

namespace calibench {

// A rectangle in its frame's xy plane, centred on the origin (normal +z; seen from both sides).
struct TexturedQuad {
  Pose world_from_quad = Pose::Identity();
  Vec2 half_size_m = Vec2::Zero();
  double albedo = 0.5;  // 0..1: grey in the image, reflectivity to the LiDAR
};

struct TexturedScene {
  std::vector<TexturedQuad> quads;
  Vec3 light_direction = Vec3(-0.4, 0.3, -0.87).normalized();  // where the light travels (world)
};

struct TexturedRoomOptions {
  double half_length_m = 7.0;  // walls at x = ±half_length
  double half_width_m = 5.0;   // walls at y = ±half_width
  double height_m = 3.0;       // ceiling
  int boxes = 10;       // boxes and pillars standing on the floor, 1.5 m or more from z's axis
  int posters = 36;     // painted rectangles on the walls
  int floor_marks = 8;  // tape and mats on the floor
  std::uint64_t seed = 1;
  bool Check(std::string* why) const;
};
TexturedScene MakeTexturedRoom(const TexturedRoomOptions& options);

struct SceneImageOptions {
  int supersampling = 2;     // samples per pixel along each axis
  double image_noise = 0.0;  // Gaussian, [0,1] intensity units
  std::uint64_t seed = 1;
  int threads = 0;  // 0 = DefaultThreads()
};
// A grey image: albedo × (ambient + diffuse) under one directional light, mid-grey where no
// surface is hit.
ImageU8 RenderSceneImage(const CameraModel& camera, const Pose& world_from_cam,
                         const TexturedScene& scene, const SceneImageOptions& options);

struct SceneScanOptions {
  double range_noise_m = 0.0;       // Gaussian, along each ray
  double azimuth_offset_rad = 0.0;  // spinning: the firing phase of this sweep
  double start_s = 0.0;             // Risley: the pattern's time at the first return
  double duration_s = 0.1;          // Risley: how long the returns are integrated (a still hold)
  std::uint64_t seed = 1;
};
// One sweep of a spinning LiDAR (rings set) or a swept scanner (no rings), as SimulateLidarScan
// fires it, against the textured scene. Intensity = albedo × 230 plus noise.
LidarCloud ScanSceneWithBeams(const BeamTable& beams, const Pose& world_from_lidar,
                              const TexturedScene& scene, const SceneScanOptions& options);
// A Livox-class scanner's returns over [start_s, start_s + duration_s) (no rings).
LidarCloud ScanSceneWithRisley(const RisleyPattern& pattern, const Pose& world_from_lidar,
                               const TexturedScene& scene, const SceneScanOptions& options);

}  // namespace calibench
