// Data of the 2D laser rangefinder (LRF) ↔ depth camera method
// (papers/lrf-depth-camera-vboard.txt, Sections 3–4), and of the LRF ↔ RGB camera checkerboard
// method (Zhang & Pless 2004). No I/O here: see core/lrf_data/dataset.h.
//
// Frames. LRF: x forward, y left, z up; the scan lies in z = 0. Depth/RGB camera: x right,
// y down, z forward (optical). The extrinsic is cam_from_lrf: x_cam = cam_from_lrf * x_lrf.
//
// The three-face target (paper Fig. 3–4). Target frame: origin at the centre of the base
// rectangle PBDQ, x to the right, y up, z out of the base towards the sensors. The base lies in
// z = 0. A, B, D lie on the base; C is raised: the "tent" is the two triangles ABC and ACD
// sharing the ridge AC. A horizontal scan crosses base (E…F), ABC (F…G), ACD (G…H), base (H…I).
//   A = (0, apex_y, 0), B = (-tent_half_width, foot_y, 0), D = (+tent_half_width, foot_y, 0),
//   C = (0, foot_y, ridge_height).
// Plane 0 = base PBDQ, plane 1 = ABC, plane 2 = ACD. Line AB = plane0 ∩ plane1,
// AC = plane1 ∩ plane2, AD = plane2 ∩ plane0 (paper Eq. (6)–(7)). Scan intersection points:
// F on AB, G on AC, H on AD.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/geometry/geometry.h"

namespace calibench {

// For the Check(std::string* why) methods of options and specs: sets *why (when given) to
// `message` and returns false.
bool FailCheck(std::string* why, const std::string& message);

// A ROS-LaserScan-like scan. ranges[i] is at angle angle_min + i * angle_increment (radians,
// counter-clockwise from +x about +z); NaN or outside [range_min, range_max] = no return.
struct LaserScan {
  double angle_min = 0.0;        // rad
  double angle_increment = 0.0;  // rad
  double range_min = 0.0;        // m
  double range_max = 0.0;        // m
  std::vector<double> ranges;    // m

  bool Valid(size_t i) const {
    const double r = ranges[i];
    return std::isfinite(r) && r >= range_min && r <= range_max && r > 0.0;
  }
  double Angle(size_t i) const { return angle_min + static_cast<double>(i) * angle_increment; }
  // Point of ray i in the LRF frame (z = 0), whether valid or not.
  Vec2 Point(size_t i) const {
    return Vec2(ranges[i] * std::cos(Angle(i)), ranges[i] * std::sin(Angle(i)));
  }
};

// Pinhole depth intrinsics (no distortion: depth cameras publish rectified depth).
struct DepthIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // pixels
  double depth_scale = 0.001;                     // metres per PNG unit
  bool Check(std::string* why) const;

  // The pinhole projection (a depth camera publishes its depth rectified: no distortion) of a
  // camera-frame point (metres) to pixels; nullopt at z <= 0. d_pixel_d_point: the 2x3 Jacobian.
  std::optional<Vec2> Project(const Vec3& point,
                              Eigen::Matrix<double, 2, 3>* d_pixel_d_point = nullptr) const;
  // The camera-frame point seen at `pixel` with depth z (along the optical axis, metres), the
  // inverse of Project; d_point_d_pixel: its 3x2 Jacobian at that depth.
  Vec3 Unproject(const Vec2& pixel, double z,
                 Eigen::Matrix<double, 3, 2>* d_point_d_pixel = nullptr) const;
};

// A depth frame: z (metres, along the optical axis) per pixel, row-major; 0 = no data.
struct DepthImage {
  DepthIntrinsics intrinsics;
  std::vector<float> depth_m;  // width * height
  float At(int u, int v) const { return depth_m[static_cast<size_t>(v) * intrinsics.width + u]; }
};

// The three-face target (frame and naming above). Metres.
struct ThreeFaceTarget {
  double base_width = 0.80;       // PBDQ along x
  double base_height = 0.60;      // PBDQ along y
  double tent_half_width = 0.25;  // |B.x| = |D.x|
  double apex_y = 0.25;           // A.y
  double foot_y = -0.25;          // B.y = D.y = C.y
  double ridge_height = 0.20;     // C.z
  bool Check(std::string* why) const;
  Vec3 A() const { return Vec3(0.0, apex_y, 0.0); }
  Vec3 B() const { return Vec3(-tent_half_width, foot_y, 0.0); }
  Vec3 C() const { return Vec3(0.0, foot_y, ridge_height); }
  Vec3 D() const { return Vec3(tent_half_width, foot_y, 0.0); }
  // Planes 0 (base), 1 (ABC), 2 (ACD) in the target frame, normals towards +z (the sensors).
  std::array<Plane, 3> FacePlanes() const;
};

// A 2D line n·p + c = 0 with |n| = 1 (LRF frame, metres).
struct Line2 {
  Vec2 normal = Vec2::UnitY();
  double offset = 0.0;
  double SignedDistance(const Vec2& p) const { return normal.dot(p) + offset; }
};

// A 3D line through `point` along unit `direction` (camera frame, metres).
struct Line3 {
  Vec3 point = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();
  double Distance(const Vec3& x) const { return (x - point).cross(direction).norm(); }
};

// Scan side of one observation (paper Section 3.1, Fig. 6).
struct ScanFeatures {
  bool ok = false;
  std::string reason;  // why not ok, in words
  // Points (LRF frame) per face: 0 = base (both outer segments), 1 = ABC, 2 = ACD.
  std::array<std::vector<Vec2>, 3> face_points;
  std::array<Line2, 3> lines;       // fitted per face (0 = base from both outer segments)
  std::array<Vec2, 3> corners;      // F = l0∩l1, G = l1∩l2, H = l2∩l0
  double rms_m = 0.0;               // RMS point-to-line distance over all face points
  std::vector<int> target_indices;  // scan ray indices on the target polyline (for display)
};

// Depth side of one observation (paper Section 3.1, Fig. 7).
struct DepthFeatures {
  bool ok = false;
  std::string reason;
  std::array<Plane, 3> planes;  // camera frame, normal towards the camera (d > 0)
  std::array<Mat4, 3> plane_covariances{Mat4::Zero(), Mat4::Zero(), Mat4::Zero()};
  std::array<Line3, 3> lines;  // AB, AC, AD
  std::array<int, 3> inlier_counts{0, 0, 0};
  double rms_m = 0.0;  // RMS point-to-plane distance over the inliers
  // Per depth pixel: -1 = not on the target, 0..2 = face (for display). May be empty.
  std::vector<signed char> face_of_pixel;
  double min_face_angle_deg = 0.0;  // smallest angle between two face normals
};

// One observation of the three-face target.
struct LrfObservation {
  std::string id;
  ScanFeatures scan;
  DepthFeatures depth;
};

// One observation of a checkerboard by the LRF and an RGB camera (Zhang & Pless 2004): scan
// points on the board and the board plane in the camera frame (from PnP).
struct LrfBoardObservation {
  std::string id;
  std::vector<Vec2> board_points;  // LRF frame
  Plane camera_plane;              // camera frame, normal towards the camera (d > 0)
  Mat4 camera_plane_covariance = Mat4::Zero();
};

// Shared by the two feature extractors (scan_lines.h, depth_planes.h).

// The face's name in reasons: "base PBDQ", "face ABC", "face ACD" for faces 0, 1, 2.
const char* FaceName(int face);
// The angle between two unit normals (of lines or planes), ignoring their sign (degrees).
double UnsignedAngleDeg(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
// "<a> and <b> are within <limit_deg>° of parallel (<angle_deg>°)": why two lines or two faces
// are refused as near parallel (their intersection would be ill-conditioned).
std::string NearParallelReason(const std::string& a, const std::string& b, double limit_deg,
                               double angle_deg);
// Why an extractor's options (called `what` in the reason) or the target cannot be used, in
// words; empty when both pass their Check.
template <typename Options>
std::string InputProblem(const Options& options, const std::string& what,
                         const ThreeFaceTarget& target) {
  std::string why;
  if (!options.Check(&why)) return "bad " + what + ": " + why;
  if (!target.Check(&why)) return "bad target: " + why;
  return "";
}

}  // namespace calibench
