// Ring inference and the projection by ID on synthetic spinning-LiDAR clouds with known rings and
// azimuth bins, and on a real VLP-16 scan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "core/io/cloud_io.h"
#include "core/lidar/cloud.h"
#include "core/lidar/lidar_image.h"
#include "core/lidar/risley_pattern.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

std::vector<double> Vlp16Elevations() {
  std::vector<double> e;
  for (int r = 0; r < 16; ++r) e.push_back((-15.0 + 2.0 * r) * kDegToRad);
  return e;
}

// HDL-64E-like: 32 upper beams about 1/3 degree apart, 32 lower beams 1/2 degree apart.
std::vector<double> Hdl64Elevations() {
  std::vector<double> e;
  for (int r = 0; r < 32; ++r) e.push_back((-24.33 + 0.5 * r) * kDegToRad);
  for (int r = 0; r < 32; ++r) e.push_back((-8.33 + 10.33 * r / 31.0) * kDegToRad);
  return e;
}

std::vector<double> Os0_128Elevations() {
  std::vector<double> e;
  for (int r = 0; r < 128; ++r) e.push_back((-45.0 + 90.0 * r / 127.0) * kDegToRad);
  return e;
}

// A spinning LiDAR inside a cylinder of radius `radius` (metres) around its z axis. Azimuth bin
// k sits at atan2 = pi - k * 2 pi / azimuths, i.e. exactly on image column k when columns =
// azimuths. Points are ring-major; ring and intensity are filled as asked.
LidarCloud CylinderScan(const std::vector<double>& elevations, int azimuths, double radius,
                        bool with_ring, bool with_intensity, double elevation_noise_rad = 0,
                        unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> radius_jitter(0.9, 1.6);
  LidarCloud cloud;
  for (size_t ring = 0; ring < elevations.size(); ++ring) {
    for (int k = 0; k < azimuths; ++k) {
      const double az = M_PI - 2 * M_PI * k / azimuths;
      const double el = elevations[ring] + elevation_noise_rad * noise(rng);
      const double rho = elevation_noise_rad > 0 ? radius * radius_jitter(rng) : radius;
      cloud.points.emplace_back(rho * std::cos(az), rho * std::sin(az), rho * std::tan(el));
      if (with_ring) cloud.ring.push_back(static_cast<int>(ring));
      if (with_intensity) cloud.intensity.push_back(static_cast<float>(ring * 10 + k % 7));
    }
  }
  cloud.width = static_cast<int>(cloud.size());
  return cloud;
}

std::vector<int> TrueRings(size_t rings, int azimuths) {
  std::vector<int> truth;
  for (size_t r = 0; r < rings; ++r) truth.insert(truth.end(), azimuths, static_cast<int>(r));
  return truth;
}

double FractionEqual(const std::vector<int>& a, const std::vector<int>& b) {
  size_t same = 0;
  for (size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
  return static_cast<double>(same) / a.size();
}

// pixel -> point and point -> pixel agree, and every point is either shown or lost to a
// nearer point in its pixel.
void ExpectConsistentMaps(const LidarCloud& cloud, const LidarImage& image) {
  ASSERT_EQ(image.point_index.size(), static_cast<size_t>(image.rows) * image.columns);
  ASSERT_EQ(image.pixel_of_point.size(), cloud.size());
  for (size_t pixel = 0; pixel < image.point_index.size(); ++pixel) {
    const int i = image.point_index[pixel];
    if (i < 0) {
      ASSERT_TRUE(std::isnan(image.range[pixel]));
      continue;
    }
    ASSERT_EQ(image.pixel_of_point[i], static_cast<int>(pixel));
    ASSERT_NEAR(image.range[pixel], cloud.points[i].norm(), 1e-5);
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    const int pixel = image.pixel_of_point[i];
    if (pixel >= 0) {
      ASSERT_EQ(image.point_index[pixel], static_cast<int>(i));
    }
  }
}

TEST(LidarImage, AzimuthColumnFollowsEq10) {
  EXPECT_EQ(AzimuthColumn({1, 0, 0}, 1800), 900);  // forward in the middle
  EXPECT_EQ(AzimuthColumn({0, 1, 0}, 1800), 450);  // left (+y) on the left
  EXPECT_EQ(AzimuthColumn({0, -1, 0}, 1800), 1350);
  EXPECT_EQ(AzimuthColumn({-1, 1e-7f, 0}, 1800), 0);   // azimuth +pi
  EXPECT_EQ(AzimuthColumn({-1, -1e-7f, 0}, 1800), 0);  // azimuth -pi wraps to the same column
  EXPECT_EQ(AzimuthColumn({-1, -0.01f, 0}, 1800), 1797);
}

TEST(LidarImage, OptionsCheck) {
  LidarImageOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.columns = -1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("columns"), std::string::npos);
  options.columns = 0;
  options.ring_gap_rad = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("ring_gap_rad"), std::string::npos);
  EXPECT_THROW(ProjectById(LidarCloud(), options), std::invalid_argument);
  options.ring_gap_rad = 0.15 * kDegToRad;
  const LidarImage empty = ProjectById(LidarCloud(), options);
  EXPECT_EQ(empty.rows, 0);
  EXPECT_TRUE(empty.point_index.empty());
}

TEST(LidarImage, ProjectsCloudWithRingField) {
  const LidarCloud cloud = CylinderScan(Vlp16Elevations(), 1800, 5.0, true, true);
  const LidarImage image = ProjectById(cloud, {});
  ASSERT_EQ(image.rows, 16);
  ASSERT_EQ(image.columns, 1800);  // automatic: the points per ring
  for (int row = 0; row < 16; ++row) {
    ASSERT_EQ(image.ring_of_row[row], 15 - row);
    for (int col = 0; col < 1800; ++col) {
      const int expected = (15 - row) * 1800 + col;  // ring-major, column k = azimuth bin k
      ASSERT_EQ(image.point_index[image.PixelIndex(row, col)], expected) << row << "," << col;
      ASSERT_EQ(image.intensity[image.PixelIndex(row, col)], cloud.intensity[expected]);
    }
  }
  ExpectConsistentMaps(cloud, image);
}

TEST(LidarImage, OrganizedCloudWithoutRingUsesRowsLowestFirst) {
  const LidarCloud scan = CylinderScan(Vlp16Elevations(), 1800, 5.0, false, true);
  // Rows as stored by a driver that puts the top beam first: the rows must be flipped.
  LidarCloud top_first;
  for (int ring = 15; ring >= 0; --ring)
    for (int k = 0; k < 1800; ++k) {
      top_first.points.push_back(scan.points[ring * 1800 + k]);
      top_first.intensity.push_back(scan.intensity[ring * 1800 + k]);
    }
  top_first.width = 1800;
  top_first.height = 16;
  ASSERT_TRUE(top_first.IsOrganized());
  std::vector<int> expected;
  for (int ring = 15; ring >= 0; --ring) expected.insert(expected.end(), 1800, ring);
  EXPECT_EQ(InferRings(top_first, {}), expected);

  LidarCloud bottom_first = scan;
  bottom_first.width = 1800;
  bottom_first.height = 16;
  EXPECT_EQ(InferRings(bottom_first, {}), TrueRings(16, 1800));

  const LidarImage image = ProjectById(top_first, {});
  ASSERT_EQ(image.rows, 16);
  // Row 0 shows the top ring, which is row 0 of this organized cloud.
  EXPECT_EQ(image.point_index[image.PixelIndex(0, 123)], 123);
  ExpectConsistentMaps(top_first, image);
}

TEST(LidarImage, UnorganizedCloudWithoutRingClustersExactly) {
  LidarCloud scan = CylinderScan(Vlp16Elevations(), 1800, 5.0, false, true);
  std::vector<size_t> order(scan.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  LidarCloud shuffled;
  std::vector<int> truth;
  const std::vector<int> rings = TrueRings(16, 1800);
  for (const size_t i : order) {
    shuffled.points.push_back(scan.points[i]);
    shuffled.intensity.push_back(scan.intensity[i]);
    truth.push_back(rings[i]);
  }
  shuffled.width = static_cast<int>(shuffled.size());
  EXPECT_EQ(InferRings(shuffled, {}), truth);

  const LidarImage image = ProjectById(shuffled, {});
  ASSERT_EQ(image.rows, 16);
  ASSERT_EQ(image.columns, 1800);
  ExpectConsistentMaps(shuffled, image);
  for (size_t j = 0; j < shuffled.size(); ++j) {
    const size_t i = order[j];  // index in the ring-major scan
    ASSERT_EQ(image.pixel_of_point[j], image.PixelIndex(15 - rings[i], static_cast<int>(i % 1800)));
  }
}

TEST(LidarImage, NearestPointWinsAndRangeStandsInForIntensity) {
  LidarCloud cloud = CylinderScan(Vlp16Elevations(), 1800, 5.0, true, false);
  const size_t n = cloud.size();
  // Same direction as point 100: one behind it (loses), one in front (wins).
  cloud.points.push_back(cloud.points[100] * 2.0f);
  cloud.points.push_back(cloud.points[100] * 0.5f);
  cloud.ring.push_back(cloud.ring[100]);
  cloud.ring.push_back(cloud.ring[100]);
  LidarImageOptions options;
  options.columns = 1800;
  const LidarImage image = ProjectById(cloud, options);
  const int pixel = image.PixelIndex(15, 100);
  EXPECT_EQ(image.point_index[pixel], static_cast<int>(n + 1));
  EXPECT_EQ(image.pixel_of_point[100], -1);
  EXPECT_EQ(image.pixel_of_point[n], -1);
  EXPECT_EQ(image.pixel_of_point[n + 1], pixel);
  EXPECT_FLOAT_EQ(image.intensity[pixel], cloud.points[n + 1].norm());  // no intensity: range
  ExpectConsistentMaps(cloud, image);

  // Neither ring nor intensity, not organized: still a full image.
  LidarCloud bare = CylinderScan(Vlp16Elevations(), 1800, 5.0, false, false);
  const LidarImage bare_image = ProjectById(bare, {});
  EXPECT_EQ(bare_image.rows, 16);
  EXPECT_EQ(std::count(bare_image.point_index.begin(), bare_image.point_index.end(), -1), 0);
  EXPECT_FLOAT_EQ(bare_image.intensity[0], bare.points[bare_image.point_index[0]].norm());
}

// Elevation noise bridges the 0.15-degree gaps between closely spaced beams; the clustering must
// still find every ring, and stray points must not renumber the rings.
TEST(LidarImage, ClusteringIsRobustForDenseAndNoisyBeamTables) {
  struct Case {
    const char* name;
    std::vector<double> elevations;
    int azimuths;
    double noise_deg;
  };
  const Case cases[] = {{"vlp16", Vlp16Elevations(), 1800, 0.1},
                        {"hdl64", Hdl64Elevations(), 1000, 0.03},
                        {"os0-128", Os0_128Elevations(), 512, 0.05}};
  for (const Case& c : cases) {
    LidarCloud cloud =
        CylinderScan(c.elevations, c.azimuths, 5.0, false, false, c.noise_deg * kDegToRad, 3);
    std::vector<int> truth = TrueRings(c.elevations.size(), c.azimuths);
    // Stray points: at the origin, and 1 degree below the lowest beam.
    for (int k = 0; k < 3; ++k) {
      cloud.points.emplace_back(0.f, 0.f, 0.f);
      truth.push_back(-1);
      const double el = c.elevations.front() - kDegToRad;
      cloud.points.emplace_back(5.f * std::cos(k), 5.f * std::sin(k), 5.f * std::tan(el));
      truth.push_back(0);
    }
    cloud.width = static_cast<int>(cloud.size());
    const std::vector<int> rings = InferRings(cloud, {});
    EXPECT_EQ(*std::max_element(rings.begin(), rings.end()),
              static_cast<int>(c.elevations.size()) - 1)
        << c.name;
    EXPECT_GT(FractionEqual(rings, truth), 0.99) << c.name;
  }
}

TEST(LidarImage, RealVlp16RingsRecoveredByClustering) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const LidarCloud cloud = LoadCloud(shared / "datasets/acfr-vlp16-chessboard/pcd/pose1_full.pcd");
  ASSERT_TRUE(cloud.HasRing());
  LidarCloud no_ring = cloud;
  no_ring.ring.clear();
  const std::vector<int> rings = InferRings(no_ring, {});
  const double fraction = FractionEqual(rings, cloud.ring);
  EXPECT_GT(fraction, 0.99);
  RecordProperty("ring_recovery_fraction", std::to_string(fraction));

  const LidarImage image = ProjectById(cloud, {});
  EXPECT_EQ(image.rows, 16);
  EXPECT_GE(image.columns, 1500);  // median points per ring (1600-1700)
  EXPECT_LE(image.columns, 1800);
  ExpectConsistentMaps(cloud, image);
  const auto shown =
      image.point_index.size() - std::count(image.point_index.begin(), image.point_index.end(), -1);
  EXPECT_GT(shown, cloud.size() * 8 / 10);  // most points get their own pixel
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// Issue 46 item 3: a cloud without rings (a Livox Mid-40's 0.1 s rosette) is drawn as an
// azimuth x elevation raster at the sensor's aspect, not as the one or two "rings" elevation
// clustering makes of it. A tenth of a second of rosette passes over ~60 % of the circle's square
// degrees; the raster's cells are sized to fill 60 % of those: over a third of the circle's cells.
TEST(LidarImage, ARinglessRosetteIsARasterOfItsField) {
  const RisleyRays rays = FireRisleyPattern(MakeRisleyPattern("mid40"), 0.0, 0.1);
  LidarCloud cloud;
  for (const Vec3& d : rays.directions) cloud.points.push_back((5.0 * d).cast<float>());
  cloud.width = static_cast<int>(cloud.size());
  const LidarImage image = ProjectById(cloud, LidarImageOptions{});
  const double cell_deg = RasterCellDeg(cloud);
  EXPECT_GT(cell_deg, 0.3);
  EXPECT_LE(cell_deg, 1.0);
  // 38.4° tall in rows of one cell, 360° wide in columns of one cell.
  EXPECT_NEAR(image.rows * cell_deg, 38.4, 2.0 * cell_deg);
  EXPECT_NEAR(image.columns * cell_deg, 360.0, cell_deg);
  EXPECT_NEAR(image.VerticalSpanRad() * kRadToDeg, 38.4, 2.0 * cell_deg);
  // Each row's returns lie in its elevation bin, top row highest.
  EXPECT_GT(image.row_elevation_rad.front(), image.row_elevation_rad.back());
  int filled = 0;
  for (int index : image.point_index) filled += index >= 0;
  const double field_cells = M_PI * 19.2 * 19.2 / (cell_deg * cell_deg);
  EXPECT_GT(filled, 0.34 * field_cells) << filled << " of ~" << field_cells;
}

}  // namespace
}  // namespace calibench
