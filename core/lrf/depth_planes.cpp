// Planes in the depth image (papers/lrf-depth-camera-vboard.txt Section 3.1 Eq. (6)–(7),
// Section 4.2 step 3, Fig. 7): the three-face target's faces and their intersection lines.
#include "core/lrf/depth_planes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace calibench {

namespace {

// ---------------------------------------------------------------------------------------------
// The depth image as points on the subsampled pixel grid.

// Every stride-th pixel back-projected, with its cell in the subsampled grid (for connectivity).
struct DepthCloud {
  std::vector<Vec3> points;   // camera frame, metres
  std::vector<Vec3> normals;  // local surface normal towards the camera; zero where unknown
  std::vector<int> pixel_u, pixel_v, cell;
  std::vector<int> point_of_cell;  // -1 = no point
  int grid_width = 0, grid_height = 0;
};

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
      cloud.points.emplace_back((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
      cloud.pixel_u.push_back(u);
      cloud.pixel_v.push_back(v);
      cloud.cell.push_back(cell);
    }
  }
  return cloud;
}

// Inlier distance at depth z: the depth noise grows with z² (stereo: σ_z = z² σ_disp / (f b)).
double PlaneThreshold(const DepthFeatureOptions& options, double z) {
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
                            const Vec3& x) {
  const double cell_m = options.stride_px * x.z() / k.fx;
  NormalWindow window;
  window.half = std::clamp(
      static_cast<int>(std::lround(1.15 * PlaneThreshold(options, x.z()) / cell_m)), 2, 8);
  window.reach_sq =
      std::pow(std::sqrt(2.0) * window.half * cell_m + 2.0 * PlaneThreshold(options, x.z()), 2);
  return window;
}

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
void ComputeNormals(const DepthIntrinsics& k, const DepthFeatureOptions& options,
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

// Local normals further than this from a plane's do not belong to it (normal noise at 3 m is a
// few degrees; the target's faces are 40° or more apart).
constexpr double kNormalToleranceDeg = 25.0;

bool IsInlier(const DepthCloud& cloud, int i, const Plane& plane,
              const DepthFeatureOptions& options) {
  return std::abs(plane.SignedDistance(cloud.points[i])) <=
             PlaneThreshold(options, cloud.points[i].z()) &&
         std::abs(cloud.normals[i].dot(plane.normal)) >= std::cos(kNormalToleranceDeg * kDegToRad);
}

// The largest 8-connected set of `members` in the subsampled pixel grid.
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

// ---------------------------------------------------------------------------------------------
// Planes in the cloud (paper Eq. (6): one plane equation per face).

struct PlanePatch {
  std::vector<int> inliers;  // indices into DepthCloud::points
  Plane plane;               // normal towards the camera (d > 0)
  Mat4 covariance = Mat4::Zero();
  double rms_m = 0.0;
};

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

// The weighted plane fit with its (n, d) covariance (FitPlaneWeighted, core/geometry).
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

// Its plane alone.
std::optional<Plane> FitPatchPlane(const DepthCloud& cloud, const std::vector<int>& indices,
                                   const DepthFeatureOptions& options) {
  std::vector<Vec3> points;
  std::vector<double> weights;
  WeightedPoints(cloud, indices, options, &points, &weights);
  return FitPlaneWeightedPlane(points, weights);
}

// Points RANSAC looks at (a random subset of the live points): plenty to find a surface of the
// min_inliers_per_face the target's faces have; the connected inliers among all points then
// refine it (ConnectedInliers). RANSAC's cost is linear in it.
constexpr size_t kRansacSamplePoints = 1500;
constexpr int kRansacMaxIterations = 200;
constexpr double kRansacConfidence = 0.999;

// One plane by RANSAC over a random subset of the live points, with the subset's inliers (cloud
// indices); nullopt when none. Each hypothesis is one point and its local normal (ComputeNormals),
// so that one good draw suffices: log(1 - confidence) / log(1 - w) draws for an inlier share w
// (16 at w = 0.35), against about 150 for three-point samples. Inliers are counted as everywhere
// else here (IsInlier: the depth-dependent distance and the normal), which needs no acos per
// point as PCL's normal-plane model does; the hypothesis with the most wins, the first on ties.
std::optional<Plane> RansacPlane(const DepthCloud& cloud, std::vector<int> live,
                                 std::mt19937_64* rng, const DepthFeatureOptions& options,
                                 std::vector<int>* ransac_inliers) {
  std::shuffle(live.begin(), live.end(), *rng);
  live.resize(std::min(live.size(), kRansacSamplePoints));
  std::vector<int> candidates;  // sample points with a normal
  std::vector<double> depths;
  for (int i : live) {
    if (!cloud.normals[i].isZero()) candidates.push_back(i);
    depths.push_back(cloud.points[i].z());
  }
  if (candidates.empty()) return std::nullopt;
  // One threshold, that of the nearer quarter: leftovers far away (where the threshold is wide)
  // must not let a plane slice through several near surfaces and win.
  const size_t quarter = depths.size() / 4;
  std::nth_element(depths.begin(), depths.begin() + quarter, depths.end());
  const double threshold = PlaneThreshold(options, depths[quarter]);
  const double min_cos = std::cos(kNormalToleranceDeg * kDegToRad);
  auto inlier = [&](int i, const Plane& plane) {
    return std::abs(plane.SignedDistance(cloud.points[i])) <= threshold &&
           std::abs(cloud.normals[i].dot(plane.normal)) >= min_cos;
  };
  std::uniform_int_distribution<size_t> pick(0, candidates.size() - 1);
  std::optional<Plane> best;
  size_t best_count = 0;
  int needed = kRansacMaxIterations;
  for (int iteration = 0; iteration < needed; ++iteration) {
    const int seed = candidates[pick(*rng)];
    const Plane plane{cloud.normals[seed], -cloud.normals[seed].dot(cloud.points[seed])};
    size_t count = 0;
    for (int i : live) count += inlier(i, plane) ? 1 : 0;
    if (count <= best_count) continue;
    best = plane;
    best_count = count;
    const double share = static_cast<double>(count) / live.size();
    if (share >= 1.0) break;
    needed = std::min(
        kRansacMaxIterations,
        static_cast<int>(std::ceil(std::log(1.0 - kRansacConfidence) / std::log(1.0 - share))));
  }
  if (!best) return std::nullopt;
  ransac_inliers->clear();
  for (int i : live)
    if (inlier(i, *best)) ransac_inliers->push_back(i);
  return best;
}

// ---------------------------------------------------------------------------------------------
// Choosing the target's three faces among the planes (Fig. 7 (c)).

double AngleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * kRadToDeg;
}

// The point where the three planes meet (A on the target); nullopt when dependent.
std::optional<Vec3> MeetingPoint(const Plane& a, const Plane& b, const Plane& c) {
  Mat3 normals;
  normals << a.normal.transpose(), b.normal.transpose(), c.normal.transpose();
  if (std::abs(normals.determinant()) < 1e-6) return std::nullopt;
  return Vec3(normals.inverse() * Vec3(-a.distance, -b.distance, -c.distance));
}

// 98th percentile of the distances from `point` to a patch's points.
double FarExtent(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  std::vector<double> d;
  for (int i : patch.inliers) d.push_back((cloud.points[i] - point).norm());
  const size_t k = std::min(d.size() - 1, static_cast<size_t>(0.98 * d.size()));
  std::nth_element(d.begin(), d.begin() + k, d.end());
  return d[k];
}

double NearestDistance(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  double best = std::numeric_limits<double>::infinity();
  for (int i : patch.inliers) best = std::min(best, (cloud.points[i] - point).norm());
  return best;
}

double MeanU(const DepthCloud& cloud, const PlanePatch& patch) {
  double sum = 0.0;
  for (int i : patch.inliers) sum += cloud.pixel_u[i];
  return sum / patch.inliers.size();
}

// Fig. 7 (c): the (base, ABC, ACD) triple whose normals make the target's angles, whose planes
// meet at a point A next to all three patches, no larger than the target, ABC left of ACD in the
// image. Walls and floor fail the angles or the size. Returns patch indices or nullopt.
std::optional<std::array<int, 3>> ChooseTriple(const DepthCloud& cloud,
                                               const std::vector<PlanePatch>& patches,
                                               const ThreeFaceTarget& target) {
  const std::array<Plane, 3> faces = target.FacePlanes();  // normals towards +z
  const std::array<double, 3> expected = {AngleDeg(faces[0].normal, faces[1].normal),
                                          AngleDeg(faces[1].normal, faces[2].normal),
                                          AngleDeg(faces[2].normal, faces[0].normal)};
  const double face_reach =
      1.15 * std::max((target.A() - target.B()).norm(), (target.A() - target.C()).norm()) + 0.05;
  double base_reach = 0.0;
  for (double sx : {-0.5, 0.5})
    for (double sy : {-0.5, 0.5})
      base_reach =
          std::max(base_reach,
                   (Vec3(sx * target.base_width, sy * target.base_height, 0) - target.A()).norm());
  base_reach = 1.15 * base_reach + 0.05;
  const double near_a = 0.3 * face_reach + 0.05;
  constexpr double kAngleTolerance = 12.0;  // degrees, per pair
  std::optional<std::array<int, 3>> best;
  double best_score = 0.0;
  const int count = static_cast<int>(patches.size());
  for (int b = 0; b < count; ++b)
    for (int f1 = 0; f1 < count; ++f1)
      for (int f2 = 0; f2 < count; ++f2) {
        if (b == f1 || b == f2 || f1 == f2) continue;
        const std::array<const PlanePatch*, 3> p = {&patches[b], &patches[f1], &patches[f2]};
        double score = 0.0;
        bool angles_match = true;
        for (int k = 0; k < 3 && angles_match; ++k) {
          const double error =
              std::abs(AngleDeg(p[k]->plane.normal, p[(k + 1) % 3]->plane.normal) - expected[k]);
          angles_match = error <= kAngleTolerance;
          score += error;
        }
        if (!angles_match || (best && score >= best_score)) continue;
        if (MeanU(cloud, *p[1]) >= MeanU(cloud, *p[2])) continue;  // ABC on the left
        const auto a = MeetingPoint(p[0]->plane, p[1]->plane, p[2]->plane);
        if (!a) continue;
        bool fits = true;
        for (int k = 0; k < 3 && fits; ++k)
          fits = NearestDistance(cloud, *p[k], *a) <= near_a &&
                 FarExtent(cloud, *p[k], *a) <= (k == 0 ? base_reach : face_reach);
        if (!fits) continue;
        best = std::array<int, 3>{b, f1, f2};
        best_score = score;
      }
  return best;
}

// Each point of the three patches goes to the one plane it is an inlier of (distance and local
// normal); points that fit two (along the edges AB, AC, AD) are left out, since they would pull
// the planes towards each other. Then the planes are fitted again.
bool ReassignAndRefit(const DepthCloud& cloud, const DepthFeatureOptions& options,
                      std::array<PlanePatch, 3>* faces) {
  std::vector<int> pool;
  for (const PlanePatch& f : *faces) pool.insert(pool.end(), f.inliers.begin(), f.inliers.end());
  std::array<std::vector<int>, 3> assigned;
  for (int i : pool) {
    int owner = -1, owners = 0;
    for (int k = 0; k < 3; ++k)
      if (IsInlier(cloud, i, (*faces)[k].plane, options)) owner = k, ++owners;
    if (owners != 1) continue;
    // A window straddling an edge can give a normal close to the dominant face's: the distance
    // to the other planes (half a threshold, ~1.5σ) catches those points.
    bool near_other = false;
    for (int k = 0; k < 3; ++k)
      near_other |= k != owner && std::abs((*faces)[k].plane.SignedDistance(cloud.points[i])) <=
                                      0.5 * PlaneThreshold(options, cloud.points[i].z());
    if (!near_other) assigned[owner].push_back(i);
  }
  std::array<PlanePatch, 3> refit;
  for (int k = 0; k < 3; ++k) {
    if (static_cast<int>(assigned[k].size()) < options.min_inliers_per_face) return false;
    auto fit = FitPatch(cloud, assigned[k], options);
    if (!fit) return false;
    refit[k] = std::move(*fit);
  }
  *faces = std::move(refit);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Sequential plane extraction (Fig. 7 (c)).

std::vector<int> LiveIndices(const std::vector<char>& live) {
  std::vector<int> indices;
  for (size_t i = 0; i < live.size(); ++i)
    if (live[i]) indices.push_back(static_cast<int>(i));
  return indices;
}

// The largest connected set of live inliers of a RANSAC plane. RANSAC's plane leans towards
// neighbouring surfaces to catch more inliers in its wide band; least squares on the connected
// inliers and a new selection pull it back.
std::vector<int> ConnectedInliers(const DepthCloud& cloud, const std::vector<int>& live_indices,
                                  const Plane& ransac_plane, const DepthFeatureOptions& options) {
  std::vector<int> inliers, component;
  Plane current = ransac_plane;
  for (int refine = 0; refine < 3; ++refine) {
    inliers.clear();
    for (int i : live_indices)
      if (IsInlier(cloud, i, current, options)) inliers.push_back(i);
    component = LargestComponent(cloud, inliers);
    if (static_cast<int>(component.size()) < options.min_inliers_per_face) break;
    const auto refit = FitPatchPlane(cloud, component, options);
    if (!refit) break;
    current = *refit;
  }
  return component;
}

// Noise tails of a surface (returns just beyond the threshold, scattered inside it) would feed
// spurious planes later: drops live points within 3 thresholds of the patch that are surrounded
// by it (5 of 8 neighbours; the edge of a neighbouring face has at most 3).
void DropNoiseTails(const DepthCloud& cloud, const PlanePatch& patch,
                    const DepthFeatureOptions& options, std::vector<char>* live) {
  std::vector<char> in_patch(cloud.point_of_cell.size(), 0);
  for (int i : patch.inliers) in_patch[cloud.cell[i]] = 1;
  for (size_t j = 0; j < live->size(); ++j) {
    if (!(*live)[j] || std::abs(patch.plane.SignedDistance(cloud.points[j])) >
                           3.0 * PlaneThreshold(options, cloud.points[j].z()))
      continue;
    int surrounding = 0;
    ForEachCellAround(cloud, cloud.cell[j], [&](int n) { surrounding += in_patch[n]; });
    if (surrounding >= 5) (*live)[j] = 0;
  }
}

// Coplanar pieces (the base on both sides of the tent) become one patch when their joint fit is
// about as good as each alone.
void MergeCoplanar(const DepthCloud& cloud, const DepthFeatureOptions& options,
                   std::vector<PlanePatch>* patches) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < patches->size() && !merged; ++a)
      for (size_t b = a + 1; b < patches->size() && !merged; ++b) {
        PlanePatch& pa = (*patches)[a];
        const PlanePatch& pb = (*patches)[b];
        if (pa.plane.normal.dot(pb.plane.normal) < std::cos(3.0 * kDegToRad)) continue;
        std::vector<int> both = pa.inliers;
        both.insert(both.end(), pb.inliers.begin(), pb.inliers.end());
        auto joint = FitPatch(cloud, both, options);
        if (!joint || joint->rms_m > 1.5 * std::max(pa.rms_m, pb.rms_m)) continue;
        pa = std::move(*joint);
        patches->erase(patches->begin() + b);
        merged = true;
      }
  }
}

// Sequential RANSAC: each plane keeps its largest connected set of inliers (a plane's inliers
// elsewhere, e.g. a band of a wall along its intersection, stay for later planes), until three
// planes look like the target. Coplanar pieces are merged afterwards.
std::vector<PlanePatch> ExtractPlanes(const DepthCloud& cloud, const ThreeFaceTarget& target,
                                      const DepthFeatureOptions& options) {
  std::vector<PlanePatch> patches;
  std::vector<char> live(cloud.points.size(), 1);
  std::mt19937_64 rng(options.seed);
  // Stop after a few RANSAC planes in a row that hold no surface: what is left is edges and
  // speckle.
  int failures_in_a_row = 0;
  for (int attempt = 0; attempt < 3 * options.max_planes && failures_in_a_row < 3 &&
                        static_cast<int>(patches.size()) < options.max_planes;
       ++attempt) {
    const std::vector<int> live_indices = LiveIndices(live);
    if (static_cast<int>(live_indices.size()) < options.min_inliers_per_face) break;
    std::vector<int> ransac_inliers;
    const auto plane = RansacPlane(cloud, live_indices, &rng, options, &ransac_inliers);
    if (!plane) break;
    const std::vector<int> component = ConnectedInliers(cloud, live_indices, *plane, options);
    std::optional<PlanePatch> patch;
    if (static_cast<int>(component.size()) >= options.min_inliers_per_face)
      patch = FitPatch(cloud, component, options);
    if (!patch) {  // a small or degenerate surface, or edge points: do not draw them again
      for (int i : component) live[i] = 0;
      for (int i : ransac_inliers) live[i] = 0;
      ++failures_in_a_row;
      continue;
    }
    failures_in_a_row = 0;
    for (int i : component) live[i] = 0;
    DropNoiseTails(cloud, *patch, options, &live);
    patches.push_back(std::move(*patch));
    if (ChooseTriple(cloud, patches, target)) break;  // the target is found: the rest is clutter
  }
  MergeCoplanar(cloud, options, &patches);
  return patches;
}

// ---------------------------------------------------------------------------------------------
// The three faces and their lines (Eq. (6)–(7)).

// Why the depth image cannot be used (intrinsics, size), in words; empty when it can.
std::string DepthImageProblem(const DepthImage& depth) {
  const DepthIntrinsics& k = depth.intrinsics;
  if (k.width <= 0 || k.height <= 0 || !(k.fx > 0) || !(k.fy > 0))
    return "depth image has no valid intrinsics (size " + std::to_string(k.width) + "x" +
           std::to_string(k.height) + ", fx and fy must be > 0)";
  if (depth.depth_m.size() != static_cast<size_t>(k.width) * k.height)
    return "depth image holds " + std::to_string(depth.depth_m.size()) + " values, expected " +
           std::to_string(k.width) + "x" + std::to_string(k.height);
  return "";
}

// The user's region clamped to the image, or the whole image.
DepthRegion ClampedRegion(const DepthIntrinsics& k, const DepthRegion* region) {
  if (!region) return DepthRegion{0, 0, k.width, k.height};
  return DepthRegion{std::clamp(region->u0, 0, k.width), std::clamp(region->v0, 0, k.height),
                     std::clamp(region->u1, 0, k.width), std::clamp(region->v1, 0, k.height)};
}

// Fig. 7 (c)–(d): segment planes, pick the target's three (base, ABC, ACD), then separate them
// and refit twice. nullopt with *reason when fewer than three faces are found.
std::optional<std::array<PlanePatch, 3>> FindFaces(const DepthCloud& cloud,
                                                   const ThreeFaceTarget& target,
                                                   const DepthFeatureOptions& options,
                                                   std::string* reason) {
  const std::vector<PlanePatch> patches = ExtractPlanes(cloud, target, options);
  const auto triple = ChooseTriple(cloud, patches, target);
  if (!triple) {
    *reason = "fewer than three faces found: " + std::to_string(patches.size()) +
              " planes with >= " + std::to_string(options.min_inliers_per_face) +
              " connected points, no three of them with the target's face angles, size and layout";
    return std::nullopt;
  }
  std::array<PlanePatch, 3> faces = {patches[(*triple)[0]], patches[(*triple)[1]],
                                     patches[(*triple)[2]]};
  for (int iteration = 0; iteration < 2; ++iteration) {
    if (!ReassignAndRefit(cloud, options, &faces)) {
      *reason = "fewer than three faces found: after separating the faces one has fewer than " +
                std::to_string(options.min_inliers_per_face) + " points";
      return std::nullopt;
    }
  }
  return faces;
}

// Sets out->min_face_angle_deg; false with a reason when two faces are within
// min_face_angle_deg of parallel (their intersection line would be ill-conditioned).
bool CheckFaceAngles(const std::array<PlanePatch, 3>& faces, const DepthFeatureOptions& options,
                     DepthFeatures* out) {
  out->min_face_angle_deg = 90.0;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const double angle = UnsignedAngleDeg(faces[a].plane.normal, faces[b].plane.normal);
    out->min_face_angle_deg = std::min(out->min_face_angle_deg, angle);
    if (angle < options.min_face_angle_deg) {
      out->reason = NearParallelReason(FaceName(a), FaceName(b), options.min_face_angle_deg, angle);
      return false;
    }
  }
  return true;
}

// The planes (Eq. (6)) with their covariances, inlier counts and RMS, and the lines of Eq. (7):
// AB = base ∩ ABC, AC = ABC ∩ ACD, AD = ACD ∩ base; each through A, where the three planes meet,
// pointing from A into the face it borders (towards B, C, D).
bool SetPlanesAndLines(const DepthCloud& cloud, const std::array<PlanePatch, 3>& faces,
                       DepthFeatures* out) {
  const auto apex = MeetingPoint(faces[0].plane, faces[1].plane, faces[2].plane);
  if (!apex) {
    out->reason = "the three faces do not meet in a point";
    return false;
  }
  auto centroid = [&](std::initializer_list<int> which) {
    Vec3 sum = Vec3::Zero();
    double n = 0;
    for (int f : which)
      for (int i : faces[f].inliers) sum += cloud.points[i], n += 1;
    return Vec3(sum / n);
  };
  const std::array<Vec3, 3> towards = {centroid({1}), centroid({1, 2}), centroid({2})};
  double sum_sq = 0.0;
  size_t total = 0;
  for (int f = 0; f < 3; ++f) {
    out->planes[f] = faces[f].plane;
    out->plane_covariances[f] = faces[f].covariance;
    out->inlier_counts[f] = static_cast<int>(faces[f].inliers.size());
    auto line = IntersectPlanes(faces[f].plane, faces[(f + 1) % 3].plane);
    if (!line) {
      out->reason = std::string(FaceName(f)) + " and " + FaceName((f + 1) % 3) + " are parallel";
      return false;
    }
    line->point = line->point + line->direction.dot(*apex - line->point) * line->direction;
    if (line->direction.dot(towards[f] - *apex) < 0) line->direction = -line->direction;
    out->lines[f] = *line;
    sum_sq += faces[f].rms_m * faces[f].rms_m * faces[f].inliers.size();
    total += faces[f].inliers.size();
  }
  out->rms_m = std::sqrt(sum_sq / total);
  return true;
}

// Per depth pixel: the face whose inlier's stride × stride block covers it, -1 elsewhere.
std::vector<signed char> FaceOfPixel(const DepthCloud& cloud,
                                     const std::array<PlanePatch, 3>& faces,
                                     const DepthIntrinsics& k, int stride) {
  std::vector<signed char> face_of_pixel(static_cast<size_t>(k.width) * k.height, -1);
  for (int f = 0; f < 3; ++f)
    for (int i : faces[f].inliers)
      for (int v = cloud.pixel_v[i]; v < std::min(k.height, cloud.pixel_v[i] + stride); ++v)
        for (int u = cloud.pixel_u[i]; u < std::min(k.width, cloud.pixel_u[i] + stride); ++u)
          face_of_pixel[static_cast<size_t>(v) * k.width + u] = static_cast<signed char>(f);
  return face_of_pixel;
}

}  // namespace

bool DepthFeatureOptions::Check(std::string* why) const {
  if (stride_px < 1) return FailCheck(why, "stride_px must be >= 1");
  if (!(max_depth_m > 0)) return FailCheck(why, "max_depth_m must be > 0 (metres)");
  if (!(plane_threshold_m > 0)) return FailCheck(why, "plane_threshold_m must be > 0 (metres)");
  if (!(plane_threshold_per_m2 >= 0))
    return FailCheck(why, "plane_threshold_per_m2 must be >= 0 (1/m)");
  if (min_inliers_per_face < 4) return FailCheck(why, "min_inliers_per_face must be >= 4");
  if (max_planes < 3) return FailCheck(why, "max_planes must be >= 3 (the target has three faces)");
  if (!(min_face_angle_deg >= 0 && min_face_angle_deg < 90))
    return FailCheck(why, "min_face_angle_deg must be in [0, 90)");
  return true;
}

DepthFeatures ExtractDepthFeatures(const DepthImage& depth, const ThreeFaceTarget& target,
                                   const DepthFeatureOptions& options, const DepthRegion* region) {
  DepthFeatures out;
  out.reason = InputProblem(options, "depth feature options", target);
  if (out.reason.empty()) out.reason = DepthImageProblem(depth);
  if (!out.reason.empty()) return out;
  const DepthIntrinsics& k = depth.intrinsics;
  DepthCloud cloud =
      BackProject(depth, ClampedRegion(k, region), options.stride_px, options.max_depth_m);
  if (cloud.points.empty()) {
    out.reason =
        region ? "no depth data inside the selected region" : "no depth data (all pixels 0)";
    return out;
  }
  ComputeNormals(k, options, &cloud);
  const std::optional<std::array<PlanePatch, 3>> faces =
      FindFaces(cloud, target, options, &out.reason);
  if (!faces) return out;
  if (!CheckFaceAngles(*faces, options, &out)) return out;
  if (!SetPlanesAndLines(cloud, *faces, &out)) return out;
  out.face_of_pixel = FaceOfPixel(cloud, *faces, k, options.stride_px);
  out.ok = true;
  return out;
}

std::optional<Line3> IntersectPlanes(const Plane& a, const Plane& b) {
  const Vec3 direction = a.normal.cross(b.normal);
  const double sq = direction.squaredNorm();
  if (direction.norm() < 1e-6) return std::nullopt;
  // The point of the line closest to the origin: p·n_a = -d_a, p·n_b = -d_b, p·dir = 0.
  Line3 line;
  line.point =
      (-a.distance * b.normal.cross(direction) - b.distance * direction.cross(a.normal)) / sq;
  line.direction = direction.normalized();
  return line;
}

}  // namespace calibench
