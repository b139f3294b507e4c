// The depth image as points on the subsampled pixel grid (back-projection, connectivity) and
// their local normals by PCA over grid neighbours (papers/lrf-depth-camera-vboard.txt Fig. 7 (b)).
#include "core/lrf/depth_cloud.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace calibench::depth {

DepthCloud BackProject(const DepthImage& depth, const DepthRegion& region, int stride,
                       double max_depth_m) {
  const DepthIntrinsics& k = depth.intrinsics;
  DepthCloud cloud;
  cloud.grid_width = std::max(0, (region.u1 - region.u0 + stride - 1) / stride);
  cloud.grid_height = std::max(0, (region.v1 - region.v0 + stride - 1) / stride);
  cloud.point_of_cell.assign(static_cast<size_t>(cloud.grid_width) * cloud.grid_height, -1);
  for (int gv = 0; gv < cloud.grid_height; ++gv) {
    for (int gu = 0; gu < cloud.grid_width; ++gu) {
      const int u = region.u0 + gu * stride, v = region.v0 + gv * stride;
      const double z = depth.At(u, v);
      if (!std::isfinite(z) || z <= 0.0 || z > max_depth_m) continue;
      const int cell = gv * cloud.grid_width + gu;
      cloud.point_of_cell[cell] = static_cast<int>(cloud.points.size());
      cloud.points.push_back(k.Unproject(Vec2(static_cast<double>(u), static_cast<double>(v)), z));
      cloud.pixel_u.push_back(u);
      cloud.pixel_v.push_back(v);
      cloud.cell.push_back(cell);
    }
  }
  return cloud;
}

NormalWindow NormalWindowAt(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                            const Vec3& x) {
  const double cell_m = options.stride_px * x.z() / k.fx;
  NormalWindow window;
  window.half = std::clamp(
      static_cast<int>(std::lround(1.15 * PlaneThreshold(options, x.z()) / cell_m)), 2, 8);
  window.reach_sq =
      std::pow(std::sqrt(2.0) * window.half * cell_m + 2.0 * PlaneThreshold(options, x.z()), 2);
  return window;
}

namespace {

// The normal of a scatter matrix (smallest eigenvector, towards the camera at x) and the RMS
// distance of the points from their plane.
std::pair<Vec3, double> NormalOfScatter(const Mat3& scatter_over_n, const Vec3& x) {
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(scatter_over_n);
  Vec3 normal = eigen.eigenvectors().col(0);
  if (normal.dot(x) > 0) normal = -normal;
  return {normal, std::sqrt(std::max(0.0, eigen.eigenvalues()(0)))};
}

// The exact neighbourhood: the grid neighbours within the reach, so that a window across a depth
// jump leaves the far side out. Zero when fewer than 6 neighbours.
Vec3 NormalFromNeighbours(const DepthCloud& cloud, size_t i, const NormalWindow& window) {
  const Vec3& x = cloud.points[i];
  const int gu = cloud.cell[i] % cloud.grid_width, gv = cloud.cell[i] / cloud.grid_width;
  Vec3 sum = Vec3::Zero();
  Mat3 sum_sq = Mat3::Zero();
  int n = 0;
  const int half = window.half;
  for (int nv = std::max(0, gv - half); nv <= std::min(cloud.grid_height - 1, gv + half); ++nv)
    for (int nu = std::max(0, gu - half); nu <= std::min(cloud.grid_width - 1, gu + half); ++nu) {
      const int j = cloud.point_of_cell[nv * cloud.grid_width + nu];
      if (j < 0) continue;
      const Vec3 d = cloud.points[j] - x;
      if (d.squaredNorm() > window.reach_sq) continue;
      sum += d;
      sum_sq += d * d.transpose();
      ++n;
    }
  if (n < 6) return Vec3::Zero();
  return NormalOfScatter((sum_sq - sum * sum.transpose() / n) / n, x).first;
}

// Summed-area tables of the grid's point moments (count, Σp, Σp·pᵀ relative to an origin): the
// moments of any window in constant time.
class MomentTables {
 public:
  explicit MomentTables(const DepthCloud& cloud) : width_(cloud.grid_width + 1) {
    if (!cloud.points.empty()) origin_ = cloud.points[cloud.points.size() / 2];
    table_.assign(static_cast<size_t>(width_) * (cloud.grid_height + 1), Moments{});
    for (int v = 0; v < cloud.grid_height; ++v) {
      Moments row;
      for (int u = 0; u < cloud.grid_width; ++u) {
        const int j = cloud.point_of_cell[v * cloud.grid_width + u];
        if (j >= 0) row.Add(cloud.points[j] - origin_);
        table_[Index(u + 1, v + 1)] = table_[Index(u + 1, v)] + row;
      }
    }
  }
  // Count and scatter / count of the cells [u0, u1] × [v0, v1] (inclusive).
  bool Window(int u0, int v0, int u1, int v1, int* n, Mat3* scatter) const {
    const Moments m = table_[Index(u1 + 1, v1 + 1)] - table_[Index(u0, v1 + 1)] -
                      table_[Index(u1 + 1, v0)] + table_[Index(u0, v0)];
    *n = static_cast<int>(std::lround(m.values[0]));
    if (*n < 6) return false;
    const Vec3 local_mean = Vec3(m.values[1], m.values[2], m.values[3]) / *n;
    Mat3 second;
    second << m.values[4], m.values[5], m.values[6], m.values[5], m.values[7], m.values[8],
        m.values[6], m.values[8], m.values[9];
    *scatter = second / *n - local_mean * local_mean.transpose();
    return true;
  }

 private:
  struct Moments {
    std::array<double, 10> values{};  // n, x, y, z, xx, xy, xz, yy, yz, zz
    void Add(const Vec3& p) {
      const double add[10] = {1,
                              p.x(),
                              p.y(),
                              p.z(),
                              p.x() * p.x(),
                              p.x() * p.y(),
                              p.x() * p.z(),
                              p.y() * p.y(),
                              p.y() * p.z(),
                              p.z() * p.z()};
      for (int k = 0; k < 10; ++k) values[k] += add[k];
    }
    Moments operator+(const Moments& o) const {
      Moments r = *this;
      for (int k = 0; k < 10; ++k) r.values[k] += o.values[k];
      return r;
    }
    Moments operator-(const Moments& o) const {
      Moments r = *this;
      for (int k = 0; k < 10; ++k) r.values[k] -= o.values[k];
      return r;
    }
  };
  size_t Index(int u, int v) const { return static_cast<size_t>(v) * width_ + u; }
  int width_;
  Vec3 origin_ = Vec3::Zero();
  std::vector<Moments> table_;
};

// Local normals by PCA over grid neighbours: they tell the faces apart where the inlier distance
// (several centimetres at 3 m) cannot, e.g. a plane slicing through the ridge of the tent.
// A window whose points all lie within half a threshold (~1.5σ) of their plane holds no depth
// jump and no ridge: its normal comes from the summed-area tables in constant time. The others
// (about one in six on the simulated target) take their neighbours one by one and leave those
// across a depth jump out.
void ComputeGridNormals(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                        DepthCloud* cloud) {
  cloud->normals.assign(cloud->points.size(), Vec3::Zero());
  const MomentTables tables(*cloud);
  // Whether a point's normal came from a planar window (the summed-area path).
  std::vector<char> planar(cloud->points.size(), 0);
  auto compute = [&](size_t i) {
    const Vec3& x = cloud->points[i];
    const NormalWindow window = NormalWindowAt(k, options, x);
    const int gu = cloud->cell[i] % cloud->grid_width, gv = cloud->cell[i] / cloud->grid_width;
    const double cell_m = options.stride_px * x.z() / k.fx;
    // The window, then (on a surface seen at a grazing angle, whose window corners lie beyond the
    // reach on the plane, where the exact neighbourhood would leave them out) the window shrunk
    // until its corners are within the reach.
    int half = window.half;
    for (int attempt = 0; attempt < 3 && half >= 1; ++attempt) {
      int n = 0;
      Mat3 scatter;
      if (!tables.Window(std::max(0, gu - half), std::max(0, gv - half),
                         std::min(cloud->grid_width - 1, gu + half),
                         std::min(cloud->grid_height - 1, gv + half), &n, &scatter))
        break;
      const auto [normal, rms] = NormalOfScatter(scatter, x);
      if (rms > 0.5 * PlaneThreshold(options, x.z())) break;
      const double corner_m =
          std::sqrt(2.0) * half * cell_m / std::max(1e-3, std::abs(normal.dot(x.normalized())));
      if (corner_m * corner_m < window.reach_sq) {
        cloud->normals[i] = normal;
        planar[i] = 1;
        return;
      }
      half =
          std::min(half - 1, static_cast<int>(0.95 * half * std::sqrt(window.reach_sq) / corner_m));
    }
    cloud->normals[i] = NormalFromNeighbours(*cloud, i, window);
  };
  // Windows of neighbouring cells share most of their points: the normals are computed on the
  // even cells, and a cell between even cells whose planar normals agree within a degree takes
  // their mean (three in four cells, on surfaces); every other cell is computed.
  const double agree = std::cos(6.0 * kDegToRad);
  for (size_t i = 0; i < cloud->points.size(); ++i) {
    const int gu = cloud->cell[i] % cloud->grid_width, gv = cloud->cell[i] / cloud->grid_width;
    if (gu % 2 == 0 && gv % 2 == 0) compute(i);
  }
  for (size_t i = 0; i < cloud->points.size(); ++i) {
    const int gu = cloud->cell[i] % cloud->grid_width, gv = cloud->cell[i] / cloud->grid_width;
    if (gu % 2 == 0 && gv % 2 == 0) continue;
    Vec3 sum = Vec3::Zero();
    Vec3 first = Vec3::Zero();
    bool usable = true;
    for (int nv = gv - gv % 2; nv <= gv + gv % 2 && usable; nv += 2)
      for (int nu = gu - gu % 2; nu <= gu + gu % 2 && usable; nu += 2) {
        const int j = nu < cloud->grid_width && nv < cloud->grid_height
                          ? cloud->point_of_cell[nv * cloud->grid_width + nu]
                          : -1;
        usable = j >= 0 && planar[j] && (first.isZero() || first.dot(cloud->normals[j]) >= agree);
        if (!usable) break;
        if (first.isZero()) first = cloud->normals[j];
        sum += cloud->normals[j];
      }
    if (usable) {
      cloud->normals[i] = sum.normalized();
    } else {
      compute(i);
    }
  }
}

// The points of `indices` with their weights w_i = 1 / t(z_i)², t the inlier threshold: they
// follow the depth noise's growth with z².
void WeightedPoints(const DepthCloud& cloud, const std::vector<int>& indices,
                    const DepthFeatureOptions& options, std::vector<Vec3>* points,
                    std::vector<double>* weights) {
  points->clear();
  weights->clear();
  for (int i : indices) {
    points->push_back(cloud.points[i]);
    const double threshold = PlaneThreshold(options, cloud.points[i].z());
    weights->push_back(1.0 / (threshold * threshold));
  }
}

}  // namespace

void ComputeNormals(const DepthIntrinsics& k, const DepthFeatureOptions& options,
                    DepthCloud* cloud) {
  if (options.normals == DepthNormalMethod::kPclIntegralImage) {
    ComputeNormalsWithPcl(k, options, cloud);
  } else {
    ComputeGridNormals(k, options, cloud);
  }
}

bool IsInlier(const DepthCloud& cloud, int i, const Plane& plane,
              const DepthFeatureOptions& options) {
  return std::abs(plane.SignedDistance(cloud.points[i])) <=
             PlaneThreshold(options, cloud.points[i].z()) &&
         std::abs(cloud.normals[i].dot(plane.normal)) >= std::cos(kNormalToleranceDeg * kDegToRad);
}

std::vector<int> LargestComponent(const DepthCloud& cloud, const std::vector<int>& members) {
  std::vector<char> in_set(cloud.point_of_cell.size(), 0), visited(in_set.size(), 0);
  for (int i : members) in_set[cloud.cell[i]] = 1;
  std::vector<int> best, current, queue;
  for (int seed : members) {
    if (visited[cloud.cell[seed]]) continue;
    current.clear();
    queue.assign(1, cloud.cell[seed]);
    visited[cloud.cell[seed]] = 1;
    while (!queue.empty()) {
      const int c = queue.back();
      queue.pop_back();
      current.push_back(cloud.point_of_cell[c]);
      ForEachCellAround(cloud, c, [&](int n) {
        if (in_set[n] && !visited[n]) {
          visited[n] = 1;
          queue.push_back(n);
        }
      });
    }
    if (current.size() > best.size()) best = current;
  }
  return best;
}

std::optional<PlanePatch> FitPatch(const DepthCloud& cloud, const std::vector<int>& indices,
                                   const DepthFeatureOptions& options) {
  std::vector<Vec3> points;
  std::vector<double> weights;
  WeightedPoints(cloud, indices, options, &points, &weights);
  const std::optional<PlaneFit> fit = FitPlaneWeighted(points, weights);
  if (!fit) return std::nullopt;
  PlanePatch patch;
  patch.inliers = indices;
  patch.plane = fit->plane;
  patch.covariance = fit->covariance;
  patch.rms_m = fit->rms_m;
  return patch;
}

std::optional<Plane> FitPatchPlane(const DepthCloud& cloud, const std::vector<int>& indices,
                                   const DepthFeatureOptions& options) {
  std::vector<Vec3> points;
  std::vector<double> weights;
  WeightedPoints(cloud, indices, options, &points, &weights);
  return FitPlaneWeightedPlane(points, weights);
}

}  // namespace calibench::depth
