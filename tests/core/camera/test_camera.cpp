// Camera models against OpenCV (cv::projectPoints, cv::fisheye::projectPoints), round trips
// through Unproject, analytic Jacobians against central differences, and Check.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

#include "core/camera/camera.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

CameraModel MakeCamera(CameraModelType type, int width, int height, double fx, double fy, double cx,
                       double cy, std::vector<double> distortion) {
  CameraModel c;
  c.type = type;
  c.width = width;
  c.height = height;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  c.distortion = std::move(distortion);
  return c;
}

// EuRoC cam0 (Kalibr radtan, 4 coefficients).
CameraModel EurocCamera() {
  return MakeCamera(CameraModelType::kPinholeRadTan, 752, 480, 458.654, 457.296, 367.215, 248.375,
                    {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
}
// ../shared udacity-chessboard-intrinsics (ROS plumb_bob, 5 coefficients).
CameraModel UdacityCamera() {
  return MakeCamera(CameraModelType::kPinholeRadTan, 964, 724, 484.130454, 484.452449, 457.177461,
                    364.861413, {-0.199619, 0.068964, 0.003371, 0.000296, 0.0});
}
// ../shared opencv-charuco-intrinsics (strong k3).
CameraModel CharucoCamera() {
  return MakeCamera(CameraModelType::kPinholeRadTan, 640, 480, 452.51072219637672,
                    456.76707935146891, 317.70297317353277, 277.75155919135995,
                    {0.12136925618707872, -1.0854664722560681, 1.1786843796668460e-04,
                     -4.6240686046485508e-04, 2.9542589406810080});
}
// A wide-angle lens with the rational model, as cv::calibrateCamera(CALIB_RATIONAL_MODEL) gives.
CameraModel RationalCamera() {
  return MakeCamera(CameraModelType::kPinholeRadTan, 1280, 800, 802.4, 801.9, 641.3, 398.7,
                    {1.8, 0.9, 0.0008, -0.0004, 0.02, 2.1, 1.6, 0.2});
}
// ../shared acfr-vlp16-chessboard camera_info.yaml (fisheye).
CameraModel Vlp16Camera() {
  return MakeCamera(CameraModelType::kKannalaBrandt, 1920, 1208, 1176.93, 1177.72, 962.275, 612.725,
                    {-0.0540096, -0.0784275, 0.0959641, -0.0515253});
}
// A near-equidistant 200-degree lens, which images points behind the camera plane.
CameraModel WideFisheyeCamera() {
  return MakeCamera(CameraModelType::kKannalaBrandt, 1280, 1024, 330.0, 330.0, 640.0, 512.0,
                    {0.02, -0.004, 0.0006, -0.00005});
}

std::vector<CameraModel> PinholeCameras() {
  return {EurocCamera(), UdacityCamera(), CharucoCamera(), RationalCamera()};
}

// Random points whose undistorted normalised coordinates span the image rectangle.
std::vector<Vec3> RandomPinholePoints(const CameraModel& c, int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-c.cx / c.fx, (c.width - c.cx) / c.fx);
  std::uniform_real_distribution<double> v(-c.cy / c.fy, (c.height - c.cy) / c.fy);
  std::uniform_real_distribution<double> depth(0.3, 30.0);
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) {
    const double z = depth(*rng);
    points.emplace_back(u(*rng) * z, v(*rng) * z, z);
  }
  return points;
}

// Random points with incidence angle in [theta_min, theta_max] (radians).
std::vector<Vec3> RandomFisheyePoints(double theta_min, double theta_max, int n,
                                      std::mt19937* rng) {
  std::uniform_real_distribution<double> theta(theta_min, theta_max);
  std::uniform_real_distribution<double> phi(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> range(0.3, 30.0);
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) {
    const double t = theta(*rng), p = phi(*rng), r = range(*rng);
    points.emplace_back(r * std::sin(t) * std::cos(p), r * std::sin(t) * std::sin(p),
                        r * std::cos(t));
  }
  return points;
}

cv::Mat CameraMatrix(const CameraModel& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

std::vector<cv::Point3d> ToCv(const std::vector<Vec3>& points) {
  std::vector<cv::Point3d> out;
  for (const Vec3& p : points) out.emplace_back(p.x(), p.y(), p.z());
  return out;
}

// Compares Project (pixels and Jacobian) with OpenCV's pixels and its d(pixel)/d(tvec), which
// equals d(pixel)/d(point) for rvec = tvec = 0; tvec_column is where OpenCV puts it.
void ExpectMatchesOpenCv(const CameraModel& c, const std::vector<Vec3>& points,
                         const std::vector<cv::Point2d>& cv_pixels, const cv::Mat& cv_jacobian,
                         int tvec_column) {
  ASSERT_EQ(cv_pixels.size(), points.size());
  double max_pixel_error = 0, max_jacobian_error = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Matrix<double, 2, 3> jacobian;
    const std::optional<Vec2> pixel = c.Project(points[i], &jacobian);
    ASSERT_TRUE(pixel) << "point " << points[i].transpose();
    max_pixel_error = std::max(
        max_pixel_error, (*pixel - Vec2(cv_pixels[i].x, cv_pixels[i].y)).cwiseAbs().maxCoeff());
    for (int r = 0; r < 2; ++r) {
      for (int k = 0; k < 3; ++k) {
        const double expected =
            cv_jacobian.at<double>(static_cast<int>(2 * i) + r, tvec_column + k);
        max_jacobian_error = std::max(max_jacobian_error, std::abs(jacobian(r, k) - expected) /
                                                              jacobian.cwiseAbs().maxCoeff());
      }
    }
  }
  EXPECT_LT(max_pixel_error, 1e-6);
  EXPECT_LT(max_jacobian_error, 1e-8);
}

TEST(CameraModelTest, NamesRoundTripAndNothingElseParses) {
  for (CameraModelType type : {CameraModelType::kPinholeRadTan, CameraModelType::kKannalaBrandt}) {
    EXPECT_EQ(ParseCameraModelName(CameraModelName(type)), type);
  }
  EXPECT_EQ(CameraModelName(CameraModelType::kPinholeRadTan), "pinhole-radtan");
  EXPECT_EQ(CameraModelName(CameraModelType::kKannalaBrandt), "kannala-brandt");
  for (const char* name :
       {"", "pinhole", "fisheye", "equidistant", "plumb_bob", "Pinhole-RadTan"}) {
    EXPECT_FALSE(ParseCameraModelName(name)) << name;
  }
}

TEST(CameraModelTest, CheckAcceptsValidModelsAndNamesTheProblem) {
  std::string why;
  for (const CameraModel& c : PinholeCameras()) EXPECT_TRUE(c.Check(&why)) << why;
  EXPECT_TRUE(Vlp16Camera().Check(&why)) << why;

  for (size_t n : {0, 1, 3, 6, 7, 9, 12, 14}) {
    CameraModel c = UdacityCamera();
    c.distortion.assign(n, 0.0);
    ASSERT_FALSE(c.Check(&why)) << n;
    EXPECT_NE(why.find("pinhole-radtan needs 4, 5 or 8"), std::string::npos) << why;
    EXPECT_NE(why.find("got " + std::to_string(n)), std::string::npos) << why;
  }
  for (size_t n : {0, 3, 5, 8}) {
    CameraModel c = Vlp16Camera();
    c.distortion.assign(n, 0.0);
    ASSERT_FALSE(c.Check(&why)) << n;
    EXPECT_EQ(why, "kannala-brandt needs exactly 4 distortion coefficients (k1 k2 k3 k4), got " +
                       std::to_string(n));
  }
  CameraModel c = UdacityCamera();
  c.fy = 0;
  EXPECT_FALSE(c.Check(&why));
  EXPECT_NE(why.find("fy=0"), std::string::npos) << why;
  c = UdacityCamera();
  c.height = 0;
  EXPECT_FALSE(c.Check(&why));
  EXPECT_NE(why.find("964x0"), std::string::npos) << why;
  c = UdacityCamera();
  c.distortion[1] = std::nan("");
  EXPECT_FALSE(c.Check(&why));
  EXPECT_NE(why.find("finite"), std::string::npos) << why;
  c = Vlp16Camera();
  c.cx = INFINITY;
  EXPECT_FALSE(c.Check(&why));
  EXPECT_FALSE(c.Check(nullptr));
}

TEST(CameraModelTest, PinholeMatchesOpenCvProjectPoints) {
  std::mt19937 rng(7);
  for (const CameraModel& c : PinholeCameras()) {
    SCOPED_TRACE("distortion count " + std::to_string(c.distortion.size()));
    const std::vector<Vec3> points = RandomPinholePoints(c, 2000, &rng);
    std::vector<cv::Point2d> cv_pixels;
    cv::Mat cv_jacobian;
    cv::projectPoints(ToCv(points), cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), CameraMatrix(c),
                      c.distortion, cv_pixels, cv_jacobian);
    ExpectMatchesOpenCv(c, points, cv_pixels, cv_jacobian, /*tvec_column=*/3);
  }
}

TEST(CameraModelTest, FisheyeMatchesOpenCvFisheyeProjectPoints) {
  std::mt19937 rng(11);
  // The VLP-16 lens is one-to-one up to about 70 degrees; its image corners are at 63 degrees.
  const CameraModel c = Vlp16Camera();
  const std::vector<Vec3> points =
      RandomFisheyePoints(0.0, 65 * std::numbers::pi / 180, 2000, &rng);
  std::vector<cv::Point2d> cv_pixels;
  cv::Mat cv_jacobian;
  cv::fisheye::projectPoints(ToCv(points), cv_pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                             CameraMatrix(c), c.distortion, 0.0, cv_jacobian);
  // cv::fisheye's Jacobian columns: f(2) c(2) k(4) rvec(3) tvec(3) alpha(1).
  ExpectMatchesOpenCv(c, points, cv_pixels, cv_jacobian, /*tvec_column=*/11);
}

TEST(CameraModelTest, PinholeRejectsPointsBehindAndBeyondTheFold) {
  const CameraModel c = UdacityCamera();
  EXPECT_FALSE(c.Project(Vec3(0.1, 0.2, 0.0)));
  EXPECT_FALSE(c.Project(Vec3(0.1, 0.2, -1.0)));
  EXPECT_FALSE(c.Project(Vec3(0, 0, 0)));
  // r_d = r (1 - 0.4 r^2) stops increasing at r = 1/sqrt(1.2) = 0.9129: beyond it a point would
  // fold back into the image.
  CameraModel folding = c;
  folding.distortion = {-0.4, 0.0, 0.0, 0.0};
  EXPECT_TRUE(folding.Project(Vec3(0.91, 0.0, 1.0)));
  EXPECT_FALSE(folding.Project(Vec3(0.915, 0.0, 1.0)));
  EXPECT_FALSE(folding.Project(Vec3(0.0, -3.0, 1.0)));
}

TEST(CameraModelTest, FisheyeRejectsRaysBeyondTheFoldAndHandlesTheAxis) {
  const CameraModel c = Vlp16Camera();
  // d theta_d / d theta < 0 at 80 degrees for these coefficients (cv::fisheye would fold it in).
  const double t = 80 * std::numbers::pi / 180, t2 = t * t;
  const auto& k = c.distortion;
  ASSERT_LT(1 + 3 * k[0] * t2 + 5 * k[1] * t2 * t2 + 7 * k[2] * std::pow(t2, 3) +
                9 * k[3] * std::pow(t2, 4),
            0.0);
  EXPECT_FALSE(c.Project(Vec3(std::sin(t), 0, std::cos(t))));
  EXPECT_FALSE(c.Project(Vec3(1.0, 0.0, -0.5)));
  EXPECT_FALSE(c.Project(Vec3(0, 0, 0)));

  Eigen::Matrix<double, 2, 3> jacobian;
  const std::optional<Vec2> center = c.Project(Vec3(0, 0, 2.0), &jacobian);
  ASSERT_TRUE(center);
  EXPECT_TRUE(test::MatrixNear(*center, Vec2(c.cx, c.cy), 0.0));
  Eigen::Matrix<double, 2, 3> expected;
  expected << c.fx / 2, 0, 0, 0, c.fy / 2, 0;
  EXPECT_TRUE(test::MatrixNear(jacobian, expected, 0.0));
  // Next to the axis the general formula must agree with the on-axis limit.
  const std::optional<Vec2> near = c.Project(Vec3(1e-9, -1e-9, 2.0), &jacobian);
  ASSERT_TRUE(near);
  EXPECT_TRUE(jacobian.allFinite());
  EXPECT_TRUE(test::MatrixNear(jacobian, expected, 1e-6));
  const std::optional<Vec3> axis = c.Unproject(Vec2(c.cx, c.cy));
  ASSERT_TRUE(axis);
  EXPECT_TRUE(test::MatrixNear(*axis, Vec3(0, 0, 1), 0.0));
}

TEST(CameraModelTest, WideFisheyeImagesPointsBehindTheCameraPlane) {
  const CameraModel c = WideFisheyeCamera();
  const double t = 100 * std::numbers::pi / 180;
  const Vec3 behind(std::sin(t) * 0.6, std::sin(t) * 0.8, std::cos(t));
  ASSERT_LT(behind.z(), 0);
  const std::optional<Vec2> pixel = c.Project(behind * 3.0);
  ASSERT_TRUE(pixel);
  const std::optional<Vec3> bearing = c.Unproject(*pixel);
  ASSERT_TRUE(bearing);
  EXPECT_TRUE(test::MatrixNear(*bearing, behind, 1e-12));
  EXPECT_FALSE(c.Project(Vec3(0.001, 0.0, -1.0)));  // 179.9 degrees
}

// Project(Unproject(pixel)) over a grid covering the whole image, borders included.
void ExpectRoundTrip(const CameraModel& c) {
  double max_error = 0, max_norm_error = 0;
  int count = 0;
  for (double y = 0; y <= c.height - 1; y += (c.height - 1) / 120.0) {
    for (double x = 0; x <= c.width - 1; x += (c.width - 1) / 160.0) {
      const std::optional<Vec3> bearing = c.Unproject(Vec2(x, y));
      ASSERT_TRUE(bearing) << "pixel " << x << " " << y;
      const std::optional<Vec2> pixel = c.Project(*bearing);
      ASSERT_TRUE(pixel) << "pixel " << x << " " << y;
      max_error = std::max(max_error, (*pixel - Vec2(x, y)).norm());
      max_norm_error = std::max(max_norm_error, std::abs(bearing->norm() - 1));
      ++count;
    }
  }
  EXPECT_GT(count, 19000);
  EXPECT_LT(max_error, 1e-6);
  EXPECT_LT(max_norm_error, 1e-14);
}

TEST(CameraModelTest, RoundTripOverTheWholeImage) {
  for (const CameraModel& c : PinholeCameras()) {
    SCOPED_TRACE("distortion count " + std::to_string(c.distortion.size()));
    ExpectRoundTrip(c);
  }
  SCOPED_TRACE("fisheye");
  ExpectRoundTrip(Vlp16Camera());
  ExpectRoundTrip(WideFisheyeCamera());
}

TEST(CameraModelTest, UnprojectFailsOutsideTheOneToOneRegion) {
  CameraModel folding = UdacityCamera();
  folding.distortion = {-0.4, 0.0, 0.0, 0.0};
  // The largest distorted radius is r_d(0.9129) = 0.6086; beyond it no point maps there.
  EXPECT_TRUE(folding.Unproject(Vec2(folding.cx + 0.60 * folding.fx, folding.cy)));
  EXPECT_FALSE(folding.Unproject(Vec2(folding.cx + 0.62 * folding.fx, folding.cy)));
  const CameraModel fisheye = Vlp16Camera();
  EXPECT_FALSE(fisheye.Unproject(Vec2(fisheye.cx + 5 * fisheye.fx, fisheye.cy)));
  EXPECT_FALSE(fisheye.Unproject(Vec2(NAN, fisheye.cy)));
}

// Central differences; the step is relative to the point's size.
Eigen::Matrix<double, 2, 3> NumericJacobian(const CameraModel& c, const Vec3& p) {
  Eigen::Matrix<double, 2, 3> j;
  const double h = 1e-5 * p.norm();
  for (int k = 0; k < 3; ++k) {
    const Vec3 dp = Vec3::Unit(k) * h;
    j.col(k) = (*c.Project(p + dp) - *c.Project(p - dp)) / (2 * h);
  }
  return j;
}

void ExpectJacobianMatchesNumeric(const CameraModel& c, const std::vector<Vec3>& points) {
  double max_relative = 0;
  for (const Vec3& p : points) {
    Eigen::Matrix<double, 2, 3> analytic;
    ASSERT_TRUE(c.Project(p, &analytic)) << p.transpose();
    const Eigen::Matrix<double, 2, 3> numeric = NumericJacobian(c, p);
    max_relative = std::max(max_relative, (analytic - numeric).norm() / analytic.norm());
  }
  EXPECT_LT(max_relative, 1e-6);
}

TEST(CameraModelTest, AnalyticJacobianMatchesCentralDifferences) {
  std::mt19937 rng(3);
  for (const CameraModel& c : PinholeCameras()) {
    SCOPED_TRACE("distortion count " + std::to_string(c.distortion.size()));
    ExpectJacobianMatchesNumeric(c, RandomPinholePoints(c, 500, &rng));
  }
  ExpectJacobianMatchesNumeric(Vlp16Camera(), RandomFisheyePoints(0.0, 1.15, 500, &rng));
  // Behind the camera plane, and close to the axis (the series branch).
  ExpectJacobianMatchesNumeric(WideFisheyeCamera(), RandomFisheyePoints(1.6, 2.9, 500, &rng));
  ExpectJacobianMatchesNumeric(WideFisheyeCamera(), RandomFisheyePoints(1e-4, 9e-3, 200, &rng));
}

// Unproject's Jacobian (the unit bearing against the pixel) against central differences, and
// Project ∘ Unproject's chain: J_project · J_unproject = I (a pixel moved is the pixel moved).
void ExpectUnprojectJacobian(const CameraModel& c, const std::vector<Vec3>& points) {
  int checked = 0;
  for (const Vec3& point : points) {
    const auto pixel = c.Project(point);
    if (!pixel) continue;
    Eigen::Matrix<double, 3, 2> analytic;
    const auto bearing = c.Unproject(*pixel, &analytic);
    if (!bearing) continue;
    Eigen::Matrix<double, 3, 2> numeric;
    bool ok = true;
    for (int k = 0; k < 2 && ok; ++k) {
      Vec2 step = Vec2::Zero();
      step[k] = 1e-3;
      const auto plus = c.Unproject(*pixel + step), minus = c.Unproject(*pixel - step);
      ok = plus && minus;
      if (ok) numeric.col(k) = (*plus - *minus) / 2e-3;
    }
    if (!ok) continue;
    EXPECT_TRUE(test::MatrixNear(analytic, numeric, 1e-7 + 1e-5 * numeric.norm()))
        << "pixel " << pixel->transpose();
    Eigen::Matrix<double, 2, 3> project;
    ASSERT_TRUE(c.Project(*bearing, &project));
    EXPECT_TRUE(test::MatrixNear(project * analytic, Eigen::Matrix2d::Identity(), 1e-6));
    EXPECT_NEAR(bearing->dot(analytic.col(0)), 0.0, 1e-9);  // stays unit
    ++checked;
  }
  EXPECT_GT(checked, static_cast<int>(points.size()) / 2);
}

TEST(CameraModelTest, UnprojectJacobianMatchesCentralDifferences) {
  std::mt19937 rng(4);
  for (const CameraModel& c : PinholeCameras()) {
    SCOPED_TRACE("distortion count " + std::to_string(c.distortion.size()));
    ExpectUnprojectJacobian(c, RandomPinholePoints(c, 300, &rng));
  }
  ExpectUnprojectJacobian(Vlp16Camera(), RandomFisheyePoints(0.0, 1.15, 300, &rng));
  ExpectUnprojectJacobian(WideFisheyeCamera(), RandomFisheyePoints(0.05, 1.5, 300, &rng));
}

}  // namespace
}  // namespace calibench
