// LiDAR points in the camera image: projection, visibility (hidden-point removal after Katz,
// Tal & Basri 2007, or a z-buffer), and colouring the cloud from the image.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/lidar/cloud.h"

namespace calibench {

struct ProjectedPoint {
  int index = 0;       // into the cloud
  Vec2 pixel;          // pixels
  double depth_m = 0;  // distance from the camera centre (metres)
};

// Points of the cloud that land inside the image (in front of the camera, within the model's
// valid field of view), with their pixel and range from the camera.
std::vector<ProjectedPoint> ProjectCloud(const CameraModel& camera, const Pose& cam_from_lidar,
                                         const LidarCloud& cloud);

struct HprOptions {
  // Spherical-flip radius as a power of the largest distance: R = max_dist * 10^radius_exponent.
  // Katz et al. recommend a large radius; 2.0-3.5 works for LiDAR scans. Unitless.
  double radius_exponent = 2.5;
  bool Check(std::string* why) const;
};

// Katz et al. 2007 "Direct visibility of point sets": spherical flip about the camera centre,
// convex hull (PCL / qhull); a point is visible iff its flipped image is a hull vertex. Takes the
// points in the camera frame; returns a visibility flag per input point.
std::vector<bool> HiddenPointRemoval(const std::vector<Vec3>& points_in_cam,
                                     const HprOptions& options);

struct ZBufferOptions {
  int cell_px = 4;              // occlusion cells of cell_px x cell_px pixels
  double depth_margin_m = 0.3;  // a point behind the nearest one in its cell by more is hidden
  bool Check(std::string* why) const;
};

// The z-buffer alternative: per image cell, keep points within depth_margin_m of the nearest.
std::vector<bool> ZBufferVisibility(const CameraModel& camera,
                                    const std::vector<ProjectedPoint>& projected,
                                    const ZBufferOptions& options);

// Colour per cloud point (BGR) sampled bilinearly from the image where the point projects and is
// visible; `has_color[i]` false elsewhere.
struct CloudColors {
  std::vector<std::uint8_t> bgr;  // 3 per point
  std::vector<bool> has_color;
};
CloudColors ColorizeCloud(const CameraModel& camera, const Pose& cam_from_lidar,
                          const LidarCloud& cloud, const ImageU8& image,
                          const std::vector<bool>& visible_per_projected,
                          const std::vector<ProjectedPoint>& projected);

}  // namespace calibench
