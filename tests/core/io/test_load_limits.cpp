// Resource limits (core/io/load_limits.h): files that declare more points, pixels or rays than
// any real sensor gives are refused from their headers, with the file, the number and the limit
// in the message, before the data is read or decoded.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lrf_data/dataset.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

fs::path Write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// The IoError of `load`, or a failure when there is none.
template <typename Load>
std::string RefusalOf(Load load) {
  try {
    load();
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no IoError)";
}

void ExpectRefusal(const std::string& message, const fs::path& file, const std::string& count,
                   const std::string& limit) {
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find(count + " is over the limit of " + limit), std::string::npos) << message;
}

std::string BigEndian32(uint32_t value) {
  return {static_cast<char>(value >> 24), static_cast<char>(value >> 16),
          static_cast<char>(value >> 8), static_cast<char>(value)};
}

// The first 33 bytes of a PNG: signature and IHDR (16-bit grey); no pixel data at all.
std::string PngHeader(uint32_t width, uint32_t height) {
  return std::string("\x89PNG\r\n\x1a\n", 8) + BigEndian32(13) + "IHDR" + BigEndian32(width) +
         BigEndian32(height) + std::string("\x10\x00\x00\x00\x00", 5) + BigEndian32(0);
}

TEST(LoadLimits, CloudsDeclaringTooManyPointsAreRefusedFromTheHeader) {
  const fs::path dir = test::TempDir("load_limits_clouds");
  const fs::path pcd = Write(dir / "huge.pcd",
                             "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                             "WIDTH 10000000\nHEIGHT 1\nPOINTS 10000000\nDATA binary\n");
  ExpectRefusal(RefusalOf([&] { LoadCloud(pcd); }), pcd, "POINTS 10000000", "5000000");
  const fs::path ply = Write(dir / "huge.ply",
                             "ply\nformat binary_little_endian 1.0\nelement vertex 10000000\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n");
  ExpectRefusal(RefusalOf([&] { LoadCloud(ply); }), ply, "the vertex count 10000000", "5000000");
  // A KITTI file has no header: its size is one. Sparse, so the test writes nothing to disk.
  const fs::path bin = dir / "huge.bin";
  std::ofstream(bin).close();
  fs::resize_file(bin, 16ull * 10'000'000);
  ExpectRefusal(RefusalOf([&] { LoadCloud(bin); }), bin, "10000000", "5000000");
  LoadLimits tight;
  tight.max_cloud_points = 2;
  const fs::path small = Write(dir / "three.pcd",
                               "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nPOINTS 3\n"
                               "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n");
  ExpectRefusal(RefusalOf([&] { LoadCloud(small, tight); }), small, "POINTS 3", "2");
  EXPECT_EQ(LoadCloud(small).size(), 3u);
}

TEST(LoadLimits, ImagesAndDepthImagesAreRefusedFromTheirHeaders) {
  const fs::path dir = test::TempDir("load_limits_images");
  const fs::path image = Write(dir / "huge.png", PngHeader(16000, 16000));
  ExpectRefusal(RefusalOf([&] { LoadImage(image); }), image, "PNG pixels (16000x16000) 256000000",
                "100000000");
  DepthIntrinsics intrinsics;
  intrinsics.width = 16000;
  intrinsics.height = 16000;
  intrinsics.fx = intrinsics.fy = 500;
  const fs::path depth = Write(dir / "huge_depth.png", PngHeader(16000, 16000));
  ExpectRefusal(RefusalOf([&] { LoadDepthPng(depth, intrinsics); }), depth,
                "depth pixels 256000000", "16777216");
  // Within the limit, a size that differs from the depth camera's is refused before decoding.
  intrinsics.width = 640;
  intrinsics.height = 480;
  const std::string wrong_size = RefusalOf([&] { LoadDepthPng(depth, intrinsics); });
  EXPECT_NE(wrong_size.find("depth pixels 256000000 is over"), std::string::npos) << wrong_size;
  const fs::path small = Write(dir / "small_depth.png", PngHeader(1280, 720));
  const std::string mismatch = RefusalOf([&] { LoadDepthPng(small, intrinsics); });
  EXPECT_NE(mismatch.find("depth PNG is 1280x720 but the depth camera is 640x480"),
            std::string::npos)
      << mismatch;
  // Formats other than PNG, JPEG and BMP never reach a decoder.
  const fs::path tiff = Write(dir / "frame.tif", std::string("II*\0\x08\0\0\0", 8));
  const std::string refused = RefusalOf([&] { LoadImage(tiff); });
  EXPECT_NE(refused.find("not a PNG, JPEG or BMP file"), std::string::npos) << refused;
  EXPECT_LT(int64_t{8000} * 6000, LoadLimits{}.max_image_pixels);  // a 48 MP camera still loads
}

TEST(LoadLimits, ScansWithTooManyRaysAreRefused) {
  const fs::path dir = test::TempDir("load_limits_scans");
  std::string ranges;
  for (int i = 0; i < 2'000'000; ++i) ranges += "1,";
  const fs::path json = Write(dir / "huge_scan.json",
                              "{\"angle_min\": 0, \"angle_increment\": 0.001, \"range_min\": 0.1, "
                              "\"range_max\": 30, \"ranges\": [" +
                                  ranges + "1]}");
  const std::string refused = RefusalOf([&] { LoadLaserScan(json); });
  EXPECT_NE(refused.find(json.string()), std::string::npos) << refused;
  EXPECT_NE(refused.find("is over the limit of 3265536"), std::string::npos) << refused;
  LoadLimits tight;
  tight.max_scan_points = 3;
  const fs::path four = Write(dir / "four.json",
                              "{\"angle_min\": 0, \"angle_increment\": 0.01, \"range_min\": 0.1, "
                              "\"range_max\": 30, \"ranges\": [1, 1, 1, 1]}");
  ExpectRefusal(RefusalOf([&] { LoadLaserScan(four, tight); }), four, "the number of ranges 4",
                "3");
  EXPECT_EQ(LoadLaserScan(four).ranges.size(), 4u);
  // A 2D PCD whose angles spread unevenly would bin into billions of rays.
  const fs::path pcd = Write(dir / "uneven.pcd",
                             "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4\nPOINTS 4\n"
                             "DATA ascii\n1 0 0\n1 0.000001 0\n1 0.000002 0\n-1 0.001 0\n");
  const std::string uneven = RefusalOf([&] { LoadLaserScan(pcd); });
  EXPECT_NE(uneven.find("the number of bins at the median angle step"), std::string::npos)
      << uneven;
}

TEST(LoadLimits, DeeplyNestedJsonIsRefusedBeforeParsing) {
  const fs::path dir = test::TempDir("load_limits_json");
  const fs::path deep =
      Write(dir / "deep.json", std::string(100000, '[') + std::string(100000, ']'));
  const std::string refused = RefusalOf([&] { LoadLaserScan(deep); });
  EXPECT_NE(refused.find("nested deeper than 64 levels"), std::string::npos) << refused;
  EXPECT_NE(refused.find(deep.string()), std::string::npos) << refused;
}

}  // namespace
}  // namespace calibench
