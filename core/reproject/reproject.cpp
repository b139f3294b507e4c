// LiDAR points in the camera image: projection, hidden-point removal (Katz, Tal & Basri 2007),
// a z-buffer, and colouring the cloud from the image.
#include "core/reproject/reproject.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/surface/convex_hull.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace calibench {
namespace {

// Points closer to the camera centre than this have no usable direction (metres).
constexpr double kMinNorm = 1e-9;
// Beyond 10^6 the flipped shell is so thin that float coordinates (what PCL hands to qhull)
// resolve depth only to ~0.06 x the largest distance; see FlipToUnitBox.
constexpr double kMaxRadiusExponent = 6.0;
// Smallest eigenvalue of the direction scatter (its eigenvalues sum to 1) below which all points
// lie on a plane (or line) through the camera centre: the 3D hull is then flat and qhull refuses
// it, so the problem is solved in that plane. Equals a thickness of 1e-6 radians.
constexpr double kFlatEigenvalue = 1e-12;

template <typename Options>
void ThrowIfInvalid(const Options& options, const char* function) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument(std::string(function) + ": " + why);
}

// The spherical flip of Katz et al.: p' = p + 2 (R - |p|) p / |p|, done in double, then moved
// and scaled into [-1, 1]^3 together with the camera centre (the origin) before the cast to
// float. Scaling does not change float's relative precision; centring halves the largest
// coordinate (the box spans the origin to the flipped shell). Rounding moves a flipped point by
// ~6e-8 R, which maps back to a depth error of the same size: 0.2 mm for R = 10^2.5 x 10 m.
// (Checked against qhull on the unrounded doubles: identical vertices on the two-plane test
// scene for exponents 2 to 6 and on a simulated OS0-128 sweep at 2.5 and 3.5.)
// The last point of the returned cloud is the camera centre.
pcl::PointCloud<pcl::PointXYZ>::Ptr FlipToUnitBox(const std::vector<Vec3>& points,
                                                  const std::vector<int>& valid, double radius,
                                                  std::vector<Vec3>* flipped) {
  flipped->clear();
  flipped->reserve(valid.size() + 1);
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // the origin is part of the set
  for (const int i : valid) {
    const Vec3& p = points[i];
    const double norm = p.norm();
    flipped->push_back(p * ((2.0 * radius - norm) / norm));
    lo = lo.cwiseMin(flipped->back());
    hi = hi.cwiseMax(flipped->back());
  }
  flipped->push_back(Vec3::Zero());
  const Vec3 centre = 0.5 * (lo + hi);
  const double scale = 2.0 / std::max((hi - lo).maxCoeff(), std::numeric_limits<double>::min());
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(flipped->size());
  for (Vec3& q : *flipped) {
    q = (q - centre) * scale;
    cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                   static_cast<float>(q.z())));
  }
  return cloud;
}

// Indices (into `cloud`) of its 3D convex hull's vertices, by PCL's qhull wrapper.
std::vector<int> HullVertices(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud) {
  pcl::ConvexHull<pcl::PointXYZ> hull;
  hull.setDimension(3);
  hull.setInputCloud(cloud);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  hull.reconstruct(vertices);
  pcl::PointIndices indices;
  hull.getHullPointIndices(indices);
  return std::vector<int>(indices.indices.begin(), indices.indices.end());
}

// Eigen decomposition of the scatter of unit directions: eigenvalues ascending, summing to 1.
Eigen::SelfAdjointEigenSolver<Mat3> DirectionScatter(const std::vector<Vec3>& points,
                                                     const std::vector<int>& valid) {
  Mat3 scatter = Mat3::Zero();
  for (const int i : valid) {
    const Vec3 u = points[i].normalized();
    scatter += u * u.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Mat3>(scatter / static_cast<double>(valid.size()));
}

// All points on one line through the camera centre: on each of its two rays only the nearest
// point can be seen.
void NearestOnEachRay(const std::vector<Vec3>& points, const std::vector<int>& valid,
                      const Vec3& axis, std::vector<bool>* visible) {
  int nearest[2] = {-1, -1};
  for (const int i : valid) {
    const int side = points[i].dot(axis) >= 0 ? 0 : 1;
    if (nearest[side] < 0 || points[i].norm() < points[nearest[side]].norm()) nearest[side] = i;
  }
  for (const int i : nearest) {
    if (i >= 0) (*visible)[i] = true;
  }
}

}  // namespace

std::vector<ProjectedPoint> ProjectCloud(const CameraModel& camera, const Pose& cam_from_lidar,
                                         const LidarCloud& cloud) {
  std::vector<ProjectedPoint> projected;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) continue;
    const Vec3 p_cam = cam_from_lidar * cloud.points[i].cast<double>();
    const std::optional<Vec2> pixel = camera.Project(p_cam);
    if (!pixel || !camera.InImage(*pixel)) continue;
    projected.push_back({static_cast<int>(i), *pixel, p_cam.norm()});
  }
  return projected;
}

bool HprOptions::Check(std::string* why) const {
  if (!std::isfinite(radius_exponent) || radius_exponent <= 0.0 ||
      radius_exponent > kMaxRadiusExponent) {
    *why =
        "HprOptions.radius_exponent must be in (0, 6] (R = max distance * 10^exponent must "
        "exceed every distance; beyond 6 float precision in the hull destroys depth), got " +
        std::to_string(radius_exponent);
    return false;
  }
  return true;
}

std::vector<bool> HiddenPointRemoval(const std::vector<Vec3>& points_in_cam,
                                     const HprOptions& options) {
  ThrowIfInvalid(options, "HiddenPointRemoval");
  std::vector<bool> visible(points_in_cam.size(), false);
  // Points without a direction from the camera centre cannot be flipped: they stay hidden.
  std::vector<int> valid;
  double max_norm = 0.0;
  for (size_t i = 0; i < points_in_cam.size(); ++i) {
    const double norm = points_in_cam[i].norm();
    if (!std::isfinite(norm) || norm < kMinNorm) continue;
    valid.push_back(static_cast<int>(i));
    max_norm = std::max(max_norm, norm);
  }
  if (valid.size() == 1) visible[valid[0]] = true;
  if (valid.size() <= 1) return visible;

  const auto scatter = DirectionScatter(points_in_cam, valid);
  const Vec3 eigenvalues = scatter.eigenvalues();
  if (eigenvalues(1) < kFlatEigenvalue) {
    NearestOnEachRay(points_in_cam, valid, scatter.eigenvectors().col(2), &visible);
    return visible;
  }
  const double radius = max_norm * std::pow(10.0, options.radius_exponent);
  std::vector<Vec3> flipped;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud = FlipToUnitBox(points_in_cam, valid, radius, &flipped);
  if (eigenvalues(0) < kFlatEigenvalue) {
    // Everything lies on a plane through the centre, where qhull refuses a flat 3D hull. Write
    // the set in that plane's coordinates and add one apex above it: the vertices of this
    // pyramid are the apex and exactly the vertices of the in-plane hull.
    const Vec3 e1 = scatter.eigenvectors().col(2), e2 = scatter.eigenvectors().col(1);
    Vec2 mean = Vec2::Zero();
    for (size_t k = 0; k < flipped.size(); ++k) {
      const Vec2 xy(flipped[k].dot(e1), flipped[k].dot(e2));
      (*cloud)[k] = pcl::PointXYZ(static_cast<float>(xy.x()), static_cast<float>(xy.y()), 0.0f);
      mean += xy / static_cast<double>(flipped.size());
    }
    cloud->push_back(
        pcl::PointXYZ(static_cast<float>(mean.x()), static_cast<float>(mean.y()), 1.0f));
  }
  // Katz et al.: p is visible iff its flipped image is a vertex of the convex hull of the
  // flipped set and the viewpoint. The viewpoint (and an apex) come after the points.
  for (const int k : HullVertices(cloud)) {
    if (k >= 0 && static_cast<size_t>(k) < valid.size()) visible[valid[k]] = true;
  }
  return visible;
}

bool ZBufferOptions::Check(std::string* why) const {
  if (cell_px < 1 || cell_px > 4096) {
    *why = "ZBufferOptions.cell_px must be in [1, 4096] pixels, got " + std::to_string(cell_px);
    return false;
  }
  if (!std::isfinite(depth_margin_m) || depth_margin_m < 0.0) {
    *why = "ZBufferOptions.depth_margin_m must be a finite distance >= 0 metres, got " +
           std::to_string(depth_margin_m);
    return false;
  }
  return true;
}

std::vector<bool> ZBufferVisibility(const CameraModel& camera,
                                    const std::vector<ProjectedPoint>& projected,
                                    const ZBufferOptions& options) {
  ThrowIfInvalid(options, "ZBufferVisibility");
  CALIBENCH_CHECK(camera.width > 0 && camera.height > 0);
  const int grid_w = (camera.width + options.cell_px - 1) / options.cell_px;
  const int grid_h = (camera.height + options.cell_px - 1) / options.cell_px;
  // Pixel centres are integers, so pixel (u, v) covers [u - 0.5, u + 0.5).
  auto cell_of = [&](const Vec2& pixel) {
    const int cx = std::clamp(static_cast<int>(std::floor((pixel.x() + 0.5) / options.cell_px)), 0,
                              grid_w - 1);
    const int cy = std::clamp(static_cast<int>(std::floor((pixel.y() + 0.5) / options.cell_px)), 0,
                              grid_h - 1);
    return static_cast<size_t>(cy) * grid_w + cx;
  };
  std::vector<double> nearest(static_cast<size_t>(grid_w) * grid_h,
                              std::numeric_limits<double>::infinity());
  for (const ProjectedPoint& p : projected) {
    double& cell = nearest[cell_of(p.pixel)];
    cell = std::min(cell, p.depth_m);
  }
  std::vector<bool> visible(projected.size());
  for (size_t k = 0; k < projected.size(); ++k) {
    visible[k] =
        projected[k].depth_m <= nearest[cell_of(projected[k].pixel)] + options.depth_margin_m;
  }
  return visible;
}

// The pixels come from `projected`, which ProjectCloud made with cam_from_lidar; the pose is
// part of the agreed signature but is not needed again here.
CloudColors ColorizeCloud(const CameraModel& camera, const Pose& /*cam_from_lidar*/,
                          const LidarCloud& cloud, const ImageU8& image,
                          const std::vector<bool>& visible_per_projected,
                          const std::vector<ProjectedPoint>& projected) {
  CALIBENCH_CHECK(visible_per_projected.size() == projected.size());
  CALIBENCH_CHECK(image.empty() || image.channels == 1 || image.channels == 3);
  CloudColors colors;
  colors.bgr.assign(3 * cloud.size(), 0);
  colors.has_color.assign(cloud.size(), false);
  if (image.empty()) return colors;
  for (size_t k = 0; k < projected.size(); ++k) {
    const ProjectedPoint& p = projected[k];
    CALIBENCH_CHECK(p.index >= 0 && static_cast<size_t>(p.index) < cloud.size());
    const double u = p.pixel.x(), v = p.pixel.y();
    // The image's own size decides (it may differ from the camera's if the caller mixed them).
    if (!visible_per_projected[k] || !camera.InImage(p.pixel) || u < -0.5 || v < -0.5 ||
        u > image.width - 0.5 || v > image.height - 0.5) {
      continue;
    }
    // Bilinear weights between the four nearest pixel centres; edges repeat the border pixel.
    const double x = std::clamp(u, 0.0, image.width - 1.0);
    const double y = std::clamp(v, 0.0, image.height - 1.0);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
    const double ax = x - x0, ay = y - y0;
    const std::uint8_t* row0 = image.Row(y0);
    const std::uint8_t* row1 = image.Row(y1);
    for (int c = 0; c < 3; ++c) {
      const int ch = image.channels == 3 ? c : 0;
      const auto at = [&](const std::uint8_t* row, int col) {
        return static_cast<double>(row[col * image.channels + ch]);
      };
      const double value = (1 - ay) * ((1 - ax) * at(row0, x0) + ax * at(row0, x1)) +
                           ay * ((1 - ax) * at(row1, x0) + ax * at(row1, x1));
      colors.bgr[3 * p.index + c] = static_cast<std::uint8_t>(std::lround(value));
    }
    colors.has_color[p.index] = true;
  }
  return colors;
}

}  // namespace calibench
