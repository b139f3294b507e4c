// Colour maps against OpenCV's reference tables (COLORMAP_VIRIDIS, COLORMAP_TURBO), viridis'
// perceptual properties, and the LiDAR image drawn from a tiny handcrafted LidarImage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/lidar/colormap.h"

namespace calibench {
namespace {

// OpenCV's 256-entry table of a colour map, as RGB.
std::vector<std::array<int, 3>> OpenCvTable(int colormap) {
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::Mat bgr;
  cv::applyColorMap(ramp, bgr, colormap);
  std::vector<std::array<int, 3>> rgb(256);
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, i);
    rgb[i] = {c[2], c[1], c[0]};
  }
  return rgb;
}

// CIELAB lightness L* (0..100) of an sRGB colour.
double Lightness(const std::array<std::uint8_t, 3>& rgb) {
  auto linear = [](std::uint8_t v) {
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  const double y = 0.2126 * linear(rgb[0]) + 0.7152 * linear(rgb[1]) + 0.0722 * linear(rgb[2]);
  return y > 216.0 / 24389.0 ? 116.0 * std::cbrt(y) - 16.0 : y * 24389.0 / 27.0;
}

void ExpectRgbNear(const std::array<std::uint8_t, 3>& actual, const std::array<int, 3>& expected,
                   int tolerance) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(actual[c], expected[c], tolerance) << "channel " << c;
}

TEST(Colormap, ViridisEndpointsAndTable) {
  // matplotlib's viridis starts dark purple and ends yellow.
  ExpectRgbNear(MapColor(Colormap::kViridis, 0.0), {68, 1, 84}, 3);
  ExpectRgbNear(MapColor(Colormap::kViridis, 1.0), {253, 231, 37}, 3);
  const auto table = OpenCvTable(cv::COLORMAP_VIRIDIS);
  for (int i = 0; i < 256; ++i) {
    SCOPED_TRACE("entry " + std::to_string(i));
    ExpectRgbNear(MapColor(Colormap::kViridis, i / 255.0), table[i], 3);
  }
}

TEST(Colormap, ViridisLightnessIncreasesMonotonically) {
  double previous = -1.0;
  for (int i = 0; i <= 64; ++i) {
    const double lightness = Lightness(MapColor(Colormap::kViridis, i / 64.0));
    EXPECT_GT(lightness, previous) << "t = " << i / 64.0;
    previous = lightness;
  }
  EXPECT_LT(Lightness(MapColor(Colormap::kViridis, 0.0)), 25.0);
  EXPECT_GT(Lightness(MapColor(Colormap::kViridis, 1.0)), 85.0);
}

TEST(Colormap, TurboFollowsGooglesTable) {
  // The published quintic approximation departs from the table most at the dark-red end.
  const auto table = OpenCvTable(cv::COLORMAP_TURBO);
  double sum = 0;
  for (int i = 0; i < 256; ++i) {
    const auto rgb = MapColor(Colormap::kTurbo, i / 255.0);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(std::abs(rgb[c] - table[i][c]), 35) << "entry " << i << " channel " << c;
      sum += std::abs(rgb[c] - table[i][c]);
    }
  }
  EXPECT_LT(sum / (3 * 256), 8.0);
  // Dark at 0, then blue, green in the middle, dark red at 1.
  const auto dark = MapColor(Colormap::kTurbo, 0.0), low = MapColor(Colormap::kTurbo, 0.1),
             mid = MapColor(Colormap::kTurbo, 0.5), high = MapColor(Colormap::kTurbo, 1.0);
  EXPECT_LT(std::max({dark[0], dark[1], dark[2]}), 70);
  EXPECT_GT(low[2], 2 * std::max(low[0], low[1]));
  EXPECT_GT(mid[1], 200);
  EXPECT_GT(high[0], 3 * high[1]);
  EXPECT_GT(high[0], 3 * high[2]);
}

TEST(Colormap, GreyAndClamping) {
  EXPECT_EQ(MapColor(Colormap::kGrey, 0.0), (std::array<std::uint8_t, 3>{0, 0, 0}));
  EXPECT_EQ(MapColor(Colormap::kGrey, 0.5), (std::array<std::uint8_t, 3>{128, 128, 128}));
  EXPECT_EQ(MapColor(Colormap::kGrey, 1.0), (std::array<std::uint8_t, 3>{255, 255, 255}));
  for (const Colormap map : {Colormap::kTurbo, Colormap::kViridis, Colormap::kGrey}) {
    EXPECT_EQ(MapColor(map, -3.0), MapColor(map, 0.0));
    EXPECT_EQ(MapColor(map, 7.0), MapColor(map, 1.0));
    EXPECT_EQ(MapColor(map, std::numeric_limits<double>::quiet_NaN()), MapColor(map, 0.0));
  }
}

// 2 rings x 3 azimuth bins with one empty pixel (row 1, column 1).
LidarImage TinyLidarImage() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  LidarImage image;
  image.rows = 2;
  image.columns = 3;
  image.point_index = {0, 1, 2, 3, -1, 4};
  image.range = {1.0f, 2.0f, 3.0f, 4.0f, nan, 5.0f};
  image.intensity = {10.0f, 10.0f, 10.0f, 10.0f, nan, 10.0f};
  image.ring_of_row = {7, 3};  // row 0 is the higher ring
  image.pixel_of_point = {0, 1, 2, 3, 5};
  return image;
}

std::array<std::uint8_t, 3> Bgr(const ImageU8& image, int row, int col) {
  const std::uint8_t* p = image.Row(row) + 3 * col;
  return {p[0], p[1], p[2]};
}

std::array<std::uint8_t, 3> Reversed(const std::array<std::uint8_t, 3>& rgb) {
  return {rgb[2], rgb[1], rgb[0]};
}

TEST(RenderLidarImage, SizeEmptyPixelsAndRangeNormalisation) {
  const LidarImage lidar = TinyLidarImage();
  const ImageU8 image = RenderLidarImage(lidar, LidarChannel::kRange, Colormap::kGrey);
  EXPECT_EQ(image.width, 3);
  EXPECT_EQ(image.height, 2);
  EXPECT_EQ(image.channels, 3);
  ASSERT_EQ(image.data.size(), 18u);
  const std::array<std::uint8_t, 3> dark{40, 40, 40};
  EXPECT_EQ(Bgr(image, 1, 1), dark);
  // Ranges 1..5: the 2 % and 98 % percentiles (nearest rank) are 1 and 4, so 5 saturates.
  EXPECT_EQ(Bgr(image, 0, 0)[0], 0);
  EXPECT_EQ(Bgr(image, 0, 1)[0], 85);  // (2 - 1) / 3
  EXPECT_EQ(Bgr(image, 1, 0)[0], 255);
  EXPECT_EQ(Bgr(image, 1, 2)[0], 255);

  // BGR order: a colour map's RGB arrives reversed.
  const ImageU8 turbo = RenderLidarImage(lidar, LidarChannel::kRange, Colormap::kTurbo);
  EXPECT_EQ(Bgr(turbo, 0, 0), Reversed(MapColor(Colormap::kTurbo, 0.0)));
  EXPECT_EQ(Bgr(turbo, 1, 1), dark);
}

TEST(RenderLidarImage, RingsByRowAndFlatIntensity) {
  const LidarImage lidar = TinyLidarImage();
  const ImageU8 rings = RenderLidarImage(lidar, LidarChannel::kRing, Colormap::kViridis);
  // Row 0 is the highest ring: the top of the colour map.
  EXPECT_EQ(Bgr(rings, 0, 2), Reversed(MapColor(Colormap::kViridis, 1.0)));
  EXPECT_EQ(Bgr(rings, 1, 0), Reversed(MapColor(Colormap::kViridis, 0.0)));
  EXPECT_EQ(Bgr(rings, 1, 1), (std::array<std::uint8_t, 3>{40, 40, 40}));
  // One intensity everywhere: no contrast, drawn mid-scale.
  const ImageU8 flat = RenderLidarImage(lidar, LidarChannel::kIntensity, Colormap::kGrey);
  EXPECT_EQ(Bgr(flat, 0, 0)[0], 128);
  EXPECT_EQ(Bgr(flat, 1, 1)[0], 40);
}

}  // namespace
}  // namespace calibench
