// Cloud file formats: exact round trips of every writer, hand-written files with unusual field
// types and layouts, real files from ../shared, and bad inputs that must raise IoError naming
// the file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "core/base/notice.h"
#include "core/io/cloud_io.h"
#include "core/lidar/cloud.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

LidarCloud RandomCloud(size_t n, bool intensity, bool ring, bool range, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-50.f, 50.f), value(0.f, 255.f);
  std::uniform_int_distribution<int> ring_id(0, 127);
  LidarCloud cloud;
  for (size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(coord(rng), coord(rng), coord(rng));
    if (intensity) cloud.intensity.push_back(value(rng));
    if (ring) cloud.ring.push_back(ring_id(rng));
    if (range) cloud.range.push_back(cloud.points.back().norm());
  }
  cloud.width = static_cast<int>(n);
  return cloud;
}

// Exact equality: every writer must reproduce the float bits.
void ExpectSameCloud(const LidarCloud& actual, const LidarCloud& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) ASSERT_EQ(actual.points[i], expected.points[i]) << i;
  EXPECT_EQ(actual.intensity, expected.intensity);
  EXPECT_EQ(actual.ring, expected.ring);
  EXPECT_EQ(actual.range, expected.range);
  EXPECT_EQ(actual.viewpoint, expected.viewpoint);
  EXPECT_EQ(actual.time_s, expected.time_s);
  EXPECT_EQ(actual.width, expected.width);
  EXPECT_EQ(actual.height, expected.height);
}

// Through the three PCD encodings and PLY and back bit for bit; the PCD header lists `fields`.
void ExpectEveryWriterRoundTrips(const fs::path& dir, const LidarCloud& cloud,
                                 const std::string& fields) {
  for (const auto encoding :
       {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    SavePcd(dir / "cloud.pcd", cloud, encoding);
    ExpectSameCloud(LoadCloud(dir / "cloud.pcd"), cloud);
  }
  EXPECT_NE(test::ReadFileBytes(dir / "cloud.pcd").find(fields), std::string::npos);
  SavePly(dir / "cloud.ply", cloud);
  ExpectSameCloud(LoadCloud(dir / "cloud.ply"), cloud);
}

void WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

template <typename T>
void Append(std::string* out, T value, bool big_endian = false) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

// Runs LoadCloud and checks for an IoError whose message names the file and the problem.
void ExpectLoadError(const fs::path& path, const std::string& problem) {
  try {
    LoadCloud(path);
    ADD_FAILURE() << "no IoError for " << path;
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << "expected '" << problem << "' in: " << what;
  }
}

const std::string kPcdHeaderXyz =
    "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\n"
    "POINTS 3\nDATA ascii\n";

TEST(CloudIo, PcdRoundTripEveryEncoding) {
  const fs::path dir = test::TempDir("cloud_io_pcd_round_trip");
  const LidarCloud cloud = RandomCloud(1000, true, true, true, 1);
  for (const auto encoding :
       {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    const fs::path path = dir / ("cloud" + std::to_string(static_cast<int>(encoding)) + ".pcd");
    SavePcd(path, cloud, encoding);
    ExpectSameCloud(LoadCloud(path), cloud);
  }
}

TEST(CloudIo, PcdRoundTripOptionalChannels) {
  const fs::path dir = test::TempDir("cloud_io_pcd_channels");
  for (int mask = 0; mask < 8; ++mask) {
    const LidarCloud cloud = RandomCloud(50, mask & 1, mask & 2, mask & 4, 10 + mask);
    for (const auto encoding : {PcdEncoding::kAscii, PcdEncoding::kBinaryCompressed}) {
      const fs::path path = dir / "cloud.pcd";
      SavePcd(path, cloud, encoding);
      ExpectSameCloud(LoadCloud(path), cloud);
    }
  }
}

// Each return's own time as the dataset contract keeps it (a field `t`, float32 seconds after
// the pair's lidar_stamp_ns) through every writer bit for bit; a driver's own PCD fields read as
// the driver wrote them (Ouster's integer nanoseconds `t`, velodyne's float seconds `time`).
TEST(CloudIo, PointTimesRoundTripEveryWriterAndDriversFieldsRead) {
  const fs::path dir = test::TempDir("cloud_io_point_times");
  LidarCloud cloud = RandomCloud(64, true, true, false, 22);
  for (size_t i = 0; i < cloud.size(); ++i) cloud.time_s.push_back(-0.1f + 0.0015f * i);
  ExpectEveryWriterRoundTrips(dir, cloud, "FIELDS x y z intensity ring t\n");
  WriteFile(dir / "ouster.pcd",
            "VERSION .7\nFIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
            "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 0\n4 5 6 48828125\n");
  const LidarCloud ouster = LoadCloud(dir / "ouster.pcd");
  ASSERT_TRUE(ouster.HasTime());
  EXPECT_FLOAT_EQ(ouster.time_s[1], 0.048828125f);
  WriteFile(dir / "velodyne.pcd",
            "VERSION .7\nFIELDS x y z intensity ring time\nSIZE 4 4 4 4 2 4\nTYPE F F F F U F\n"
            "COUNT 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
            "1 2 3 7 0 -0.0995\n4 5 6 9 1 -0.05\n");
  const LidarCloud velodyne = LoadCloud(dir / "velodyne.pcd");
  ASSERT_TRUE(velodyne.HasTime());
  EXPECT_FLOAT_EQ(velodyne.time_s[0], -0.0995f);
  // Seconds on a clock where the contract keeps seconds after the stamp: said, and not read.
  WriteFile(dir / "clock.pcd",
            "VERSION .7\nFIELDS x y z t\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 1604515190.25\n");
  EXPECT_FALSE(LoadCloud(dir / "clock.pcd").HasTime());
  // A writer refuses times that are not one per point.
  cloud.time_s.pop_back();
  EXPECT_THROW(SavePcd(dir / "short.pcd", cloud, PcdEncoding::kBinary), IoError);
}

// Each return's ray origin (a swept scanner's mirror) as PCL's PointWithViewpoint stores it:
// vp_x, vp_y, vp_z, through every writer and back bit for bit; a reader's own field order.
TEST(CloudIo, ViewpointsRoundTripEveryWriter) {
  const fs::path dir = test::TempDir("cloud_io_viewpoints");
  LidarCloud cloud = RandomCloud(64, true, false, false, 21);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> offset(-0.1f, 0.1f);
  for (size_t i = 0; i < cloud.size(); ++i)
    cloud.viewpoint.emplace_back(offset(rng), offset(rng), offset(rng));
  ExpectEveryWriterRoundTrips(dir, cloud, "FIELDS x y z intensity vp_x vp_y vp_z");
  // PCL writes PointWithViewpoint's fields in its own order; only a complete triple counts.
  WriteFile(dir / "pcl.pcd",
            "VERSION .7\nFIELDS x y z vp_x vp_y vp_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"
            "COUNT 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
            "1 2 3 0.1 0 0.05\n4 5 6 0.2 0 -0.05\n");
  const LidarCloud pcl = LoadCloud(dir / "pcl.pcd");
  ASSERT_TRUE(pcl.HasViewpoint());
  EXPECT_EQ(pcl.viewpoint[1], Eigen::Vector3f(0.2f, 0.f, -0.05f));
  EXPECT_EQ(pcl.RayOrigin(0), Eigen::Vector3d(0.1f, 0.f, 0.05f));
  WriteFile(dir / "partial.pcd",
            "VERSION .7\nFIELDS x y z vp_x\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 0.1\n");
  EXPECT_FALSE(LoadCloud(dir / "partial.pcd").HasViewpoint());
  WriteFile(dir / "nan.pcd",
            "VERSION .7\nFIELDS x y z vp_x vp_y vp_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\n"
            "COUNT 1 1 1 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 nan 0 0\n");
  try {
    LoadCloud(dir / "nan.pcd");
    ADD_FAILURE() << "a viewpoint that is not finite was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("nan.pcd"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("viewpoint"), std::string::npos) << e.what();
  }
}

TEST(CloudIo, PcdWritesRingAsU2) {
  const fs::path path = test::TempDir("cloud_io_ring_u2") / "cloud.pcd";
  SavePcd(path, RandomCloud(5, true, true, false, 2), PcdEncoding::kAscii);
  const std::string text = test::ReadFileBytes(path);
  EXPECT_NE(text.find("FIELDS x y z intensity ring\nSIZE 4 4 4 4 2\nTYPE F F F F U\n"),
            std::string::npos)
      << text;
  LidarCloud bad = RandomCloud(5, false, true, false, 2);
  bad.ring[3] = 70000;
  EXPECT_THROW(SavePcd(path, bad), IoError);
}

TEST(CloudIo, PlyAndKittiRoundTrip) {
  const fs::path dir = test::TempDir("cloud_io_ply_kitti");
  const LidarCloud cloud = RandomCloud(777, true, true, true, 3);
  SavePly(dir / "cloud.ply", cloud);
  ExpectSameCloud(LoadCloud(dir / "cloud.ply"), cloud);

  SaveKittiBin(dir / "cloud.bin", cloud);
  EXPECT_EQ(fs::file_size(dir / "cloud.bin"), 777u * 16u);
  LidarCloud xyzi = cloud;  // KITTI keeps x y z intensity only
  xyzi.ring.clear();
  xyzi.range.clear();
  ExpectSameCloud(LoadCloud(dir / "cloud.bin"), xyzi);
}

TEST(CloudIo, OrganizedCloudKeepsItsGrid) {
  const fs::path dir = test::TempDir("cloud_io_organized");
  LidarCloud cloud = RandomCloud(16 * 100, true, true, false, 4);
  cloud.width = 100;
  cloud.height = 16;
  ASSERT_TRUE(cloud.IsOrganized());
  for (const auto encoding :
       {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    SavePcd(dir / "organized.pcd", cloud, encoding);
    const LidarCloud loaded = LoadCloud(dir / "organized.pcd");
    EXPECT_TRUE(loaded.IsOrganized());
    ExpectSameCloud(loaded, cloud);
  }
  // One NaN point: it is dropped and the grid is gone (width = size, height = 1).
  cloud.points[17].x() = std::numeric_limits<float>::quiet_NaN();
  SavePcd(dir / "holed.pcd", cloud, PcdEncoding::kBinary);
  const LidarCloud holed = LoadCloud(dir / "holed.pcd");
  EXPECT_EQ(holed.size(), 1599u);
  EXPECT_EQ(holed.height, 1);
  EXPECT_EQ(holed.width, 1599);
  EXPECT_EQ(holed.ring[17], cloud.ring[18]);
  EXPECT_FALSE(holed.IsOrganized());
}

// ring as I1 (ascii), an extra COUNT 3 field before it, intensity named "i", rgb after.
TEST(CloudIo, ReadsHandWrittenAsciiPcdWithOddFields) {
  const fs::path path = test::TempDir("cloud_io_ascii_odd") / "odd.pcd";
  WriteFile(path,
            "# hand-written\nVERSION .7\nFIELDS x y z normal i ring rgb\nSIZE 4 4 8 4 2 1 4\n"
            "TYPE F F F F U I F\nCOUNT 1 1 1 3 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
            "POINTS 2\nDATA ascii\n1.5 -2 3.25 0.1 0.2 0.3 77 5 4.2e-38\r\n"
            "\n-1e1 +2 nan 9 9 9 1 12 0\n");
  const LidarCloud cloud = LoadCloud(path);
  ASSERT_EQ(cloud.size(), 1u);  // the NaN point is dropped
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(1.5f, -2.f, 3.25f));
  EXPECT_EQ(cloud.intensity, std::vector<float>{77.f});
  EXPECT_EQ(cloud.ring, std::vector<int>{5});
  EXPECT_TRUE(cloud.range.empty());
}

// Binary PCDs with ring as U4 and as F, and a COUNT 3 field in the middle of the record.
TEST(CloudIo, ReadsHandWrittenBinaryPcdWithOddRingTypes) {
  const fs::path dir = test::TempDir("cloud_io_binary_odd");
  for (const std::string ring_type : {"U 4", "F 4", "I 1"}) {
    std::string bytes = "VERSION 0.6\nFIELDS x y z extra ring intensity\nSIZE 4 4 4 2 " +
                        ring_type.substr(2) + " 8\nTYPE F F F I " + ring_type.substr(0, 1) +
                        " F\nCOUNT 1 1 1 3 1 1\n"
                        "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n";
    for (int i = 0; i < 3; ++i) {
      Append(&bytes, 0.5f * i);
      Append(&bytes, -1.0f * i);
      Append(&bytes, 2.0f + i);
      for (int k = 0; k < 3; ++k) Append(&bytes, static_cast<int16_t>(-7));
      if (ring_type == "U 4") Append(&bytes, static_cast<uint32_t>(10 + i));
      if (ring_type == "F 4") Append(&bytes, static_cast<float>(10 + i));
      if (ring_type == "I 1") Append(&bytes, static_cast<int8_t>(10 + i));
      Append(&bytes, 100.0 + i);
    }
    WriteFile(dir / "odd.pcd", bytes);
    const LidarCloud cloud = LoadCloud(dir / "odd.pcd");
    ASSERT_EQ(cloud.size(), 3u) << ring_type;
    EXPECT_EQ(cloud.points[2], Eigen::Vector3f(1.f, -2.f, 4.f)) << ring_type;
    EXPECT_EQ(cloud.ring, (std::vector<int>{10, 11, 12})) << ring_type;
    EXPECT_EQ(cloud.intensity, (std::vector<float>{100.f, 101.f, 102.f})) << ring_type;
  }
}

// An element before the vertices (with a list property) and faces after them.
TEST(CloudIo, ReadsAsciiAndBigEndianPly) {
  const fs::path dir = test::TempDir("cloud_io_ply_read");
  WriteFile(dir / "ascii.ply",
            "ply\nformat ascii 1.0\ncomment test\nelement camera 1\nproperty list uchar int ids\n"
            "element vertex 2\nproperty double x\nproperty float y\nproperty float z\n"
            "property uchar ring\nproperty short intensity\nproperty float range\nend_header\n"
            "3 1 2 3\n1 2 3 4 -5 3.7\n4 5 6 7 8 8.8\n3 0 1 1\n");
  const LidarCloud ascii = LoadCloud(dir / "ascii.ply");
  ASSERT_EQ(ascii.size(), 2u);
  EXPECT_EQ(ascii.points[1], Eigen::Vector3f(4.f, 5.f, 6.f));
  EXPECT_EQ(ascii.ring, (std::vector<int>{4, 7}));
  EXPECT_EQ(ascii.intensity, (std::vector<float>{-5.f, 8.f}));
  EXPECT_EQ(ascii.range, (std::vector<float>{3.7f, 8.8f}));

  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uint16 ring\nproperty list uchar float normals\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 2; ++i) {
    for (float v : {1.25f + i, -2.5f, 3.f}) Append(&bytes, v, true);
    Append(&bytes, static_cast<uint16_t>(300 + i), true);
    Append(&bytes, static_cast<uint8_t>(2));
    Append(&bytes, 0.f, true);
    Append(&bytes, 1.f, true);
  }
  bytes += "garbage face data";
  WriteFile(dir / "big.ply", bytes);
  const LidarCloud big = LoadCloud(dir / "big.ply");
  ASSERT_EQ(big.size(), 2u);
  EXPECT_EQ(big.points[1], Eigen::Vector3f(2.25f, -2.5f, 3.f));
  EXPECT_EQ(big.ring, (std::vector<int>{300, 301}));
  EXPECT_FALSE(big.HasIntensity());
}

TEST(CloudIo, RealVlp16Scan) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const LidarCloud cloud = LoadCloud(shared / "datasets/acfr-vlp16-chessboard/pcd/pose1_full.pcd");
  ASSERT_EQ(cloud.size(), 23969u);
  ASSERT_EQ(cloud.ring.size(), 23969u);
  ASSERT_EQ(cloud.intensity.size(), 23969u);
  EXPECT_EQ(cloud.height, 1);
  EXPECT_EQ(*std::min_element(cloud.ring.begin(), cloud.ring.end()), 0);
  EXPECT_EQ(*std::max_element(cloud.ring.begin(), cloud.ring.end()), 15);
  EXPECT_EQ(std::count(cloud.ring.begin(), cloud.ring.end(), 0), 1067);
  // First row of the file: 1.373171 -2.6457233 -0.79871565 4 0
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(1.373171f, -2.6457233f, -0.79871565f));
  EXPECT_EQ(cloud.intensity[0], 4.f);
  // Ring 0 is the lowest beam (-15 degrees).
  const Eigen::Vector3f p = cloud.points[0];
  EXPECT_NEAR(std::atan2(p.z(), p.head<2>().norm()) * 180 / M_PI, -15.0, 0.01);
}

TEST(CloudIo, Real2dLidarScansWithRgbOnly) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  int files = 0;
  for (const auto& entry :
       fs::directory_iterator(shared / "datasets/acfr-rpg-2dlidar-chessboard/lasers")) {
    if (entry.path().extension() != ".pcd") continue;
    ++files;
    const LidarCloud cloud = LoadCloud(entry.path());
    EXPECT_GE(cloud.size(), 505u) << entry.path();
    EXPECT_LE(cloud.size(), 507u) << entry.path();
    EXPECT_FALSE(cloud.HasIntensity());
    EXPECT_FALSE(cloud.HasRing());
    EXPECT_TRUE(cloud.range.empty());
    for (const auto& p : cloud.points) ASSERT_EQ(p.z(), 0.f);
  }
  EXPECT_EQ(files, 5);
}

TEST(CloudIo, BadInputsNameTheFileAndTheProblem) {
  const fs::path dir = test::TempDir("cloud_io_bad");
  ExpectLoadError(dir / "missing.pcd", "does not exist");
  WriteFile(dir / "cloud.xyz", "1 2 3\n");
  ExpectLoadError(dir / "cloud.xyz", "unknown cloud extension");

  // Truncated binary data.
  SavePcd(dir / "truncated.pcd", RandomCloud(100, true, false, false, 5), PcdEncoding::kBinary);
  std::string bytes = test::ReadFileBytes(dir / "truncated.pcd");
  WriteFile(dir / "truncated.pcd", bytes.substr(0, bytes.size() - 10));
  ExpectLoadError(dir / "truncated.pcd",
                  "expected 1600 bytes of point data (POINTS x point size), file has 1590");

  // Truncated ascii: a missing row, and a row cut in the middle.
  WriteFile(dir / "rows.pcd", kPcdHeaderXyz + "1 2 3\n4 5 6\n");
  ExpectLoadError(dir / "rows.pcd", "expected 3 points of ascii data, file has 2 rows");
  WriteFile(dir / "cut.pcd", kPcdHeaderXyz + "1 2 3\n4 5 6\n7 8");
  ExpectLoadError(dir / "cut.pcd", "line 12 has 2 values, expected 3");
  WriteFile(dir / "word.pcd", kPcdHeaderXyz + "1 2 3\n4 five 6\n7 8 9\n");
  ExpectLoadError(dir / "word.pcd", "cannot parse 'five'");

  // Data beyond what the header declares is read as PCL reads it: POINTS points, the rest not
  // at all (said once, on stderr). A real road frame carries 3,870 zero bytes after its
  // binary_compressed block (tests/core/io/test_pcd_as_pcl.cpp).
  const int noted = NotedCount("pcd-trailing-data");
  WriteFile(dir / "extra.pcd", kPcdHeaderXyz + "1 2 3\n4 5 6\n7 8 9\n10 11 12\n\n");
  const LidarCloud extra = LoadCloud(dir / "extra.pcd");
  ASSERT_EQ(extra.size(), 3u);
  EXPECT_EQ(extra.points[2], Eigen::Vector3f(7, 8, 9));
  WriteFile(dir / "blank_tail.pcd", kPcdHeaderXyz + "1 2 3\n4 5 6\n7 8 9\n\n  \n");
  EXPECT_EQ(LoadCloud(dir / "blank_tail.pcd").size(), 3u);  // trailing blank lines are no data
  EXPECT_EQ(NotedCount("pcd-trailing-data"), noted + 1);
  for (const PcdEncoding encoding : {PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    const LidarCloud written = RandomCloud(100, true, false, false, 5);
    SavePcd(dir / "long.pcd", written, encoding);
    WriteFile(dir / "long.pcd", test::ReadFileBytes(dir / "long.pcd") + std::string(16, '\0'));
    const LidarCloud read = LoadCloud(dir / "long.pcd");
    ASSERT_EQ(read.size(), written.size());
    for (size_t i = 0; i < read.size(); ++i) ASSERT_EQ(read.points[i], written.points[i]) << i;
  }
  EXPECT_EQ(NotedCount("pcd-trailing-data"), noted + 3);
  // Less than the header declares is still an error.
  SavePcd(dir / "short.pcd", RandomCloud(100, false, false, false, 6),
          PcdEncoding::kBinaryCompressed);
  bytes = test::ReadFileBytes(dir / "short.pcd");
  WriteFile(dir / "short.pcd", bytes.substr(0, bytes.size() - 4));
  ExpectLoadError(dir / "short.pcd", "bytes of compressed point data, file has");

  // Not a regular file: a FIFO would block and a device would never end; a loop of symbolic
  // links is named as such.
  ASSERT_EQ(::mkfifo((dir / "fifo.pcd").c_str(), 0600), 0);
  ExpectLoadError(dir / "fifo.pcd", "is not a regular file");
  fs::create_symlink("/dev/zero", dir / "zero.bin");
  ExpectLoadError(dir / "zero.bin", "is not a regular file");
  fs::create_symlink(dir / "loop_b.pcd", dir / "loop_a.pcd");
  fs::create_symlink(dir / "loop_a.pcd", dir / "loop_b.pcd");
  ExpectLoadError(dir / "loop_a.pcd", "symbolic links");

  // Header problems.
  WriteFile(dir / "noz.pcd",
            "FIELDS x y intensity\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\n"
            "DATA ascii\n1 2 3\n");
  ExpectLoadError(dir / "noz.pcd", "no 'z' field");
  WriteFile(dir / "type.pcd",
            "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n");
  ExpectLoadError(dir / "type.pcd", "field 'z' has TYPE F with SIZE 2");
  WriteFile(dir / "data.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA zip\n");
  ExpectLoadError(dir / "data.pcd", "unknown PCD DATA type 'zip'");
  WriteFile(dir / "garbage.pcd", "\x01\x02garbage\n");
  ExpectLoadError(dir / "garbage.pcd", "is this a PCD file?");

  // Corrupt compressed data.
  SavePcd(dir / "lzf.pcd", RandomCloud(100, false, false, false, 6),
          PcdEncoding::kBinaryCompressed);
  bytes = test::ReadFileBytes(dir / "lzf.pcd");
  const size_t data = bytes.find("DATA binary_compressed\n") + 23 + 8;
  for (size_t i = data; i < bytes.size(); ++i) bytes[i] = static_cast<char>(0xff);
  WriteFile(dir / "lzf.pcd", bytes);
  ExpectLoadError(dir / "lzf.pcd", "LZF decompression");

  // NaN points are dropped; a cloud of NaN points only is an error.
  WriteFile(dir / "nan.pcd", kPcdHeaderXyz + "nan nan nan\n1 2 3\n4 inf 6\n");
  EXPECT_EQ(LoadCloud(dir / "nan.pcd").size(), 1u);
  WriteFile(dir / "allnan.pcd", kPcdHeaderXyz + "nan nan nan\nnan 2 3\n4 -inf 6\n");
  ExpectLoadError(dir / "allnan.pcd", "none of its 3 points has finite x, y, z");

  // KITTI: 20 bytes is not a whole number of points.
  WriteFile(dir / "kitti.bin", std::string(20, '\0'));
  ExpectLoadError(dir / "kitti.bin", "not a multiple of 16");

  // PLY: truncated vertices, no vertex element.
  WriteFile(dir / "short.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n");
  ExpectLoadError(dir / "short.ply", "PLY data ends inside vertex 1");
  WriteFile(dir / "face.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n");
  ExpectLoadError(dir / "face.ply", "no vertex element");

  // Writers: a folder that does not exist is the caller's job, and an error here.
  EXPECT_THROW(SavePcd(dir / "no/such/dir/a.pcd", RandomCloud(3, false, false, false, 7)), IoError);
  EXPECT_THROW(SavePly(dir / "no/such/dir/a.ply", RandomCloud(3, false, false, false, 7)), IoError);
}

}  // namespace
}  // namespace calibench
