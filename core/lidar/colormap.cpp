// Colour maps as closed-form polynomials (no lookup tables) and the LiDAR image as a picture.
#include "core/lidar/colormap.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/base/types.h"

namespace calibench {
namespace {

// Empty pixels of the LiDAR image (BGR), dark enough not to read as a low value of any map.
constexpr std::uint8_t kEmptyGrey = 40;
// Robust range for intensity and range: values outside these percentiles saturate.
constexpr double kLowPercentile = 0.02;
constexpr double kHighPercentile = 0.98;

std::uint8_t ToByte(double unit) {
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(unit, 0.0, 1.0)));
}

// Turbo (Anton Mikhailov, Google 2019) by the published polynomial approximation of Ruofei Du
// (Apache-2.0): a quintic per channel. It departs from Google's 256-entry table by up to
// ~32/255 at the dark-red end (mean ~6/255); the hue order is kept.
std::array<std::uint8_t, 3> Turbo(double x) {
  const double v[6] = {1.0, x, x * x, x * x * x, x * x * x * x, x * x * x * x * x};
  constexpr double kRed[6] = {0.13572138,   4.61539260,    -42.66032258,
                              132.13108234, -152.94239396, 59.28637943};
  constexpr double kGreen[6] = {0.09140261,   2.19418839, 4.84296658,
                                -14.18503333, 4.27729857, 2.82956604};
  constexpr double kBlue[6] = {0.10667330,   12.64194608,  -60.58204836,
                               110.36276771, -89.90310912, 27.34824973};
  double r = 0, g = 0, b = 0;
  for (int k = 0; k < 6; ++k) {
    r += kRed[k] * v[k];
    g += kGreen[k] * v[k];
    b += kBlue[k] * v[k];
  }
  return {ToByte(r), ToByte(g), ToByte(b)};
}

// Viridis (van der Walt & Smith, matplotlib) as a degree-7 least-squares polynomial per channel,
// fitted by us to the 256 matplotlib samples (as shipped in OpenCV's COLORMAP_VIRIDIS). Largest
// deviation from the table 3/255 after rounding (mean 0.55/255); test_colormap.cpp checks it.
std::array<std::uint8_t, 3> Viridis(double t) {
  // Rows: coefficients of t^0 .. t^7; columns: R, G, B in [0, 1].
  constexpr double kCoeff[8][3] = {
      {0.256677081566, 0.00407480325649, 0.323477080812},
      {1.14946180893, 1.497903462, 1.95411529998},
      {-14.6286375189, -1.20169440042, -7.72815980349},
      {75.572915215, 2.29027562245, 24.5151851348},
      {-215.528531895, -8.27756060158, -64.3807833775},
      {325.263228067, 18.8007555908, 109.509155451},
      {-237.506696701, -18.9682192565, -100.261463227},
      {66.4179266081, 6.76128042755, 36.2058713377},
  };
  std::array<std::uint8_t, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    double value = 0;  // Horner
    for (int k = 7; k >= 0; --k) value = value * t + kCoeff[k][c];
    rgb[c] = ToByte(value);
  }
  return rgb;
}

// The value at quantile q of `values` (not empty), by nearest rank.
float Percentile(std::vector<float> values, double q) {
  const size_t k = static_cast<size_t>(std::floor(q * (values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// Maps a channel's values to [0, 1] between its 2 % and 98 % percentiles.
struct RobustRange {
  double low = 0, high = 0;
  double Normalise(double value) const {
    // A flat channel (one value everywhere) has no contrast to show: draw it mid-scale.
    if (!(high > low)) return 0.5;
    return std::clamp((value - low) / (high - low), 0.0, 1.0);
  }
};

RobustRange RangeOf(const LidarImage& image, const std::vector<float>& channel) {
  std::vector<float> values;
  for (size_t k = 0; k < channel.size(); ++k) {
    if (image.point_index[k] >= 0 && std::isfinite(channel[k])) values.push_back(channel[k]);
  }
  if (values.empty()) return {};
  return {Percentile(values, kLowPercentile), Percentile(values, kHighPercentile)};
}

}  // namespace

std::array<std::uint8_t, 3> MapColor(Colormap map, double t) {
  t = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0);
  switch (map) {
    case Colormap::kTurbo:
      return Turbo(t);
    case Colormap::kViridis:
      return Viridis(t);
    case Colormap::kGrey:
      break;
  }
  const std::uint8_t grey = ToByte(t);
  return {grey, grey, grey};
}

ImageU8 RenderLidarImage(const LidarImage& image, LidarChannel channel, Colormap map) {
  const size_t pixels = static_cast<size_t>(image.rows) * image.columns;
  CALIBENCH_CHECK(image.point_index.size() == pixels);
  const std::vector<float>& values =
      channel == LidarChannel::kRange ? image.range : image.intensity;
  CALIBENCH_CHECK(channel == LidarChannel::kRing || values.size() == pixels);
  const RobustRange range = channel == LidarChannel::kRing ? RobustRange{} : RangeOf(image, values);

  ImageU8 out;
  out.width = image.columns;
  out.height = image.rows;
  out.channels = 3;
  out.data.assign(pixels * 3, kEmptyGrey);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.columns; ++col) {
      const size_t k = static_cast<size_t>(image.PixelIndex(row, col));
      if (image.point_index[k] < 0) continue;
      double t = 0;
      if (channel == LidarChannel::kRing) {
        // Rings by their count: the lowest row (lowest ring) 0, the top row 1. Row rank rather
        // than the ring id, since ids of a cloud may skip numbers.
        t = image.rows > 1 ? static_cast<double>(image.rows - 1 - row) / (image.rows - 1) : 0.5;
      } else {
        if (!std::isfinite(values[k])) continue;
        t = range.Normalise(values[k]);
      }
      const std::array<std::uint8_t, 3> rgb = MapColor(map, t);
      std::uint8_t* bgr = out.Row(row) + 3 * col;
      bgr[0] = rgb[2];
      bgr[1] = rgb[1];
      bgr[2] = rgb[0];
    }
  }
  return out;
}

}  // namespace calibench
