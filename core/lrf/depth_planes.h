// Planes in the depth image: the three-face target's faces and their intersection lines
// (papers/lrf-depth-camera-vboard.txt Section 3.1 Eq. (6)–(7), Section 4.2 step 3, Fig. 7).
//
// Back-projection, RANSAC (one point and its local normal per draw) for the planes in view, the
// target's three faces chosen among them, and the three pairwise intersection lines AB, AC, AD.
// Faces are named by the target frame (types.h), assuming the target stands upright (its y axis
// roughly up in the image): ABC is the face on the camera's left.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/lrf_data/types.h"

namespace calibench {

// How the local normals are estimated: PCA over grid neighbours with a depth-dependent window
// that leaves points across a depth jump out (ours, the default), or PCL's
// IntegralImageNormalEstimation (covariance method, one window size for the image), kept for the
// comparison in depth_pcl.cpp's header comment.
enum class DepthNormalMethod { kGridPca, kPclIntegralImage };
// How each RANSAC round draws its plane: one point and its normal per draw (ours, the default),
// or PCL's SACSegmentationFromNormals with SACMODEL_NORMAL_PLANE (three points per draw).
enum class DepthPlaneSearch { kPointNormalRansac, kPclSacNormalPlane };

struct DepthFeatureOptions {
  int stride_px = 2;  // back-project every stride-th pixel in u and v
  double max_depth_m = 6.0;
  // RANSAC inlier distance: base + per_m2 · z² (the depth noise grows with z²), metres.
  double plane_threshold_m = 0.008;
  double plane_threshold_per_m2 = 0.004;
  int min_inliers_per_face = 150;
  int max_planes = 8;               // planes extracted before choosing the target's three
  double min_face_angle_deg = 8.0;  // faces closer to parallel fail with a reason
  uint64_t seed = 7;                // RANSAC sampling
  DepthNormalMethod normals = DepthNormalMethod::kGridPca;
  DepthPlaneSearch plane_search = DepthPlaneSearch::kPointNormalRansac;
  bool Check(std::string* why) const;
};

// Optional pixel rectangle [u0, u1) × [v0, v1) holding the target (the user's selection).
struct DepthRegion {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

// The target's face planes and their intersection lines (camera frame, metres), inside `region`
// when given. Fails with a reason (bad options or image, no depth data, fewer than three faces
// found, faces near parallel).
DepthFeatures ExtractDepthFeatures(const DepthImage& depth, const ThreeFaceTarget& target,
                                   const DepthFeatureOptions& options,
                                   const DepthRegion* region = nullptr);

// The intersection line of two planes (their frame, metres); nullopt when they are parallel
// within 1e-6.
std::optional<Line3> IntersectPlanes(const Plane& a, const Plane& b);

}  // namespace calibench
