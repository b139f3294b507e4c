#include "core/lidar_plane.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

namespace calibench {

bool LidarPlaneOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(ransac_threshold_m > 0)) return fail("ransac_threshold_m must be > 0 (metres)");
  if (ransac_iterations < 1) return fail("ransac_iterations must be >= 1");
  if (min_inliers < 4) return fail("min_inliers must be >= 4");
  if (!(min_inlier_fraction >= 0 && min_inlier_fraction <= 1))
    return fail("min_inlier_fraction must be in [0, 1]");
  return true;
}

std::vector<int> SelectSeedRegion(const LidarCloud& cloud, const LidarSeed& seed) {
  std::vector<int> indices;
  const Eigen::Vector3f centre = seed.point.cast<float>();
  const float radius_sq = static_cast<float>(seed.radius * seed.radius);
  for (size_t i = 0; i < cloud.size(); ++i)
    if ((cloud.points[i] - centre).squaredNorm() <= radius_sq)
      indices.push_back(static_cast<int>(i));
  return indices;
}

std::vector<int> SelectBrushRegion(const LidarImage& image, const std::vector<int>& pixels) {
  std::vector<int> indices;
  for (int pixel : pixels) {
    if (pixel < 0 || pixel >= static_cast<int>(image.point_index.size())) continue;
    if (image.point_index[pixel] >= 0) indices.push_back(image.point_index[pixel]);
  }
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  return indices;
}

std::optional<LidarPlaneFit> FitPlaneLeastSquares(const LidarCloud& cloud,
                                                  const std::vector<int>& indices) {
  if (indices.size() < 4) return std::nullopt;
  Vec3 centroid = Vec3::Zero();
  for (int i : indices) centroid += cloud.points[i].cast<double>();
  centroid /= static_cast<double>(indices.size());
  Mat3 scatter = Mat3::Zero();
  for (int i : indices) {
    const Vec3 p = cloud.points[i].cast<double>() - centroid;
    scatter += p * p.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);
  // Points on a line (or a single ring) do not define a plane.
  if (eigen.eigenvalues()[1] < 1e-6 * eigen.eigenvalues()[2] || eigen.eigenvalues()[1] <= 0)
    return std::nullopt;
  LidarPlaneFit fit;
  fit.plane = OrientTowardsOrigin(
      Plane{eigen.eigenvectors().col(0), -eigen.eigenvectors().col(0).dot(centroid)});
  fit.inliers = indices;
  fit.num_candidates = static_cast<int>(indices.size());
  double sum_sq = 0.0;
  for (int i : indices)
    sum_sq += std::pow(fit.plane.SignedDistance(cloud.points[i].cast<double>()), 2);
  fit.rms_m = std::sqrt(sum_sq / indices.size());
  // Covariance: residual r_i = n·x_i + d, with n perturbed in its tangent plane (basis B):
  // J_i = [x_iᵀ B, 1], Σ = σ² (JᵀJ)⁻¹ with σ² from the residuals (3 parameters).
  Eigen::Matrix<double, 3, 2> tangent;
  tangent.col(0) = fit.plane.normal.unitOrthogonal();
  tangent.col(1) = fit.plane.normal.cross(tangent.col(0));
  Mat3 normal_matrix = Mat3::Zero();
  for (int i : indices) {
    Eigen::RowVector3d j;
    j << cloud.points[i].cast<double>().transpose() * tangent, 1.0;
    normal_matrix += j.transpose() * j;
  }
  const double dof = std::max<double>(1.0, static_cast<double>(indices.size()) - 3.0);
  const Mat3 local_cov = (sum_sq / dof) * normal_matrix.inverse();
  Eigen::Matrix<double, 4, 3> to_coefficients = Eigen::Matrix<double, 4, 3>::Zero();
  to_coefficients.topLeftCorner<3, 2>() = tangent;
  to_coefficients(3, 2) = 1.0;
  fit.covariance = to_coefficients * local_cov * to_coefficients.transpose();
  return fit;
}

std::optional<LidarPlaneFit> FitBoardPlane(const LidarCloud& cloud,
                                           const std::vector<int>& candidates,
                                           const LidarPlaneOptions& options, std::string* why) {
  auto fail = [&](const std::string& m) -> std::optional<LidarPlaneFit> {
    if (why) *why = m;
    return std::nullopt;
  };
  if (candidates.empty()) return fail("the selected LiDAR region holds no points");
  if (static_cast<int>(candidates.size()) < options.min_inliers)
    return fail("the selected LiDAR region holds only " + std::to_string(candidates.size()) +
                " points (need " + std::to_string(options.min_inliers) + ")");

  // PCL's RANSAC draws from a fixed internal seed; shuffling the candidates with our own seed
  // makes the sampling depend on options.seed and on nothing else.
  std::vector<int> order = candidates;
  std::mt19937_64 rng(options.seed);
  std::shuffle(order.begin(), order.end(), rng);
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->reserve(order.size());
  for (int i : order)
    points->push_back(pcl::PointXYZ(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z()));
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(points, false));
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, options.ransac_threshold_m);
  ransac.setMaxIterations(options.ransac_iterations);
  if (!ransac.computeModel()) return fail("RANSAC found no plane in the selected LiDAR region");
  std::vector<int> local_inliers;
  ransac.getInliers(local_inliers);

  // Least-squares refit on the inliers, then one re-selection with the refined plane.
  std::vector<int> inliers;
  for (int k : local_inliers) inliers.push_back(order[k]);
  std::optional<LidarPlaneFit> fit = FitPlaneLeastSquares(cloud, inliers);
  if (!fit) return fail("the RANSAC inliers lie on a line (a single ring?): no plane");
  std::vector<int> refined;
  for (int i : candidates)
    if (std::abs(fit->plane.SignedDistance(cloud.points[i].cast<double>())) <=
        options.ransac_threshold_m)
      refined.push_back(i);
  if (refined.size() >= 4) {
    if (auto again = FitPlaneLeastSquares(cloud, refined)) fit = again;
  }
  fit->num_candidates = static_cast<int>(candidates.size());
  const int n = static_cast<int>(fit->inliers.size());
  if (n < options.min_inliers)
    return fail("plane has only " + std::to_string(n) + " inliers (need " +
                std::to_string(options.min_inliers) + ")");
  if (n < options.min_inlier_fraction * candidates.size())
    return fail("plane explains only " + std::to_string(n) + " of " +
                std::to_string(candidates.size()) + " selected points");
  return fit;
}

}  // namespace calibench
