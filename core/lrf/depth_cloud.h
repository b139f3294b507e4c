// The depth image as points on its subsampled pixel grid, their local normals, connectivity and
// the sequential plane search over them: what depth_planes.cpp chooses the target's faces from.
// Internal to core/lrf (depth_cloud.cpp, depth_plane_search.cpp, depth_pcl.cpp, depth_planes.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "core/lrf/depth_planes.h"

namespace calibench::depth {

// Every stride-th pixel back-projected, with its cell in the subsampled grid (for connectivity).
struct DepthCloud {
  std::vector<Vec3> points;   // camera frame, metres
  std::vector<Vec3> normals;  // local surface normal towards the camera; zero where unknown
  std::vector<int> pixel_u, pixel_v, cell;
  std::vector<int> point_of_cell;  // -1 = no point
  int grid_width = 0, grid_height = 0;
};

// A plane found in the cloud (paper Eq. (6): one plane equation per face) with its points.
struct PlanePatch {
  std::vector<int> inliers;  // indices into DepthCloud::points
  Plane plane;               // normal towards the camera (d > 0)
  Mat4 covariance = Mat4::Zero();
  double rms_m = 0.0;
};

DepthCloud BackProject(const DepthImage& depth, const DepthRegion& region, int stride,
                       double max_depth_m);

// Inlier distance at depth z: the depth noise grows with z² (stereo: σ_z = z² σ_disp / (f b)).
inline double PlaneThreshold(const DepthFeatureOptions& options, double z) {
  return options.plane_threshold_m + options.plane_threshold_per_m2 * z * z;
}

// Calls visit(n) for each cell n of the 3×3 block around `cell` (itself included) inside the
// grid: 8-connectivity on the subsampled pixel grid.
template <typename Visit>
void ForEachCellAround(const DepthCloud& cloud, int cell, Visit visit) {
  const int gu = cell % cloud.grid_width, gv = cell / cloud.grid_width;
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const int nu = gu + du, nv = gv + dv;
      if (nu >= 0 && nv >= 0 && nu < cloud.grid_width && nv < cloud.grid_height)
        visit(nv * cloud.grid_width + nu);
    }
}

// The half window (cells) of point x's normal and the reach of its neighbours (metres). The
// window's spread must exceed the depth noise (σ ≈ threshold / 3) by about twice, else the
// smallest eigenvector is noise: half-width ≈ 1.15 · threshold / cell, 2 to 8 cells. The reach is
// the window plus the noise (a jump to the wall behind is a metre or more).
struct NormalWindow {
  int half = 0;
  double reach_sq = 0.0;
};
NormalWindow NormalWindowAt(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                            const Vec3& x);

// Sets cloud->normals by options.normals: our grid PCA (depth_cloud.cpp) or PCL's integral-image
// estimation (depth_pcl.cpp).
void ComputeNormals(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                    DepthCloud* cloud);
void ComputeNormalsWithPcl(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                           DepthCloud* cloud);

// Local normals further than this from a plane's do not belong to it (normal noise at 3 m is a
// few degrees; the target's faces are 40° or more apart).
constexpr double kNormalToleranceDeg = 25.0;

// Within the depth-dependent distance of the plane, with a local normal along it.
bool IsInlier(const DepthCloud& cloud, int i, const Plane& plane,
              const DepthFeatureOptions& options);

// The largest 8-connected set of `members` in the subsampled pixel grid.
std::vector<int> LargestComponent(const DepthCloud& cloud, const std::vector<int>& members);

// The weighted plane fit (weights 1 / threshold(z)²) with its (n, d) covariance; nullopt when
// degenerate. FitPatchPlane: its plane alone.
std::optional<PlanePatch> FitPatch(const DepthCloud& cloud, const std::vector<int>& indices,
                                   const DepthFeatureOptions& options);
std::optional<Plane> FitPatchPlane(const DepthCloud& cloud, const std::vector<int>& indices,
                                   const DepthFeatureOptions& options);

// What one RANSAC round looks at: a random subset of the live points, those of them with a
// normal, and one inlier distance for all.
struct RansacSample {
  std::vector<int> points;
  std::vector<int> with_normal;
  double threshold_m = 0.0;
};
// RANSAC's limits (ours and PCL's).
constexpr int kRansacMaxIterations = 200;
constexpr double kRansacConfidence = 0.999;

// A RANSAC plane over the sample by PCL's SACSegmentationFromNormals (SACMODEL_NORMAL_PLANE),
// for the comparison with ours (depth_pcl.cpp). The PCL clouds are built once per cloud: call the
// returned function per round.
using PlaneSearch = std::function<std::optional<Plane>(const RansacSample&)>;
PlaneSearch MakePclPlaneSearch(const DepthCloud& cloud);

// Sequential RANSAC: each plane keeps its largest connected set of inliers, until
// target_found(patches) or no surface is left; coplanar pieces are merged afterwards.
std::vector<PlanePatch> ExtractPlanes(
    const DepthCloud& cloud, const DepthFeatureOptions& options,
    const std::function<bool(const std::vector<PlanePatch>&)>& target_found);

}  // namespace calibench::depth
