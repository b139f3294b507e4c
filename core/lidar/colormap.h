// Perceptual colour maps for ranges, intensities and rings (turbo, viridis), and the LiDAR image
// drawn as a picture.
#pragma once

#include <array>
#include <cstdint>

#include "core/base/image.h"
#include "core/lidar/lidar_image.h"

namespace calibench {

enum class Colormap { kTurbo, kViridis, kGrey };
// t in [0, 1] (clamped) to RGB.
std::array<std::uint8_t, 3> MapColor(Colormap map, double t);

enum class LidarChannel { kIntensity, kRange, kRing };
// The projection-by-ID image as a BGR picture (rows x columns); empty pixels dark grey.
// Intensity and range are normalised by robust percentiles (2 % – 98 %), rings by their count.
ImageU8 RenderLidarImage(const LidarImage& image, LidarChannel channel, Colormap map);

}  // namespace calibench
