// LiDAR point clouds with optional per-point intensity, ring and range, and their file formats.
#pragma once

#include <filesystem>
#include <vector>

#include "core/types.h"

namespace calibench {

struct LidarCloud {
  std::vector<Eigen::Vector3f> points;  // metres, LiDAR frame
  std::vector<float> intensity;         // empty when the file has none
  std::vector<int> ring;                // laser index, 0 = lowest beam; empty when unknown
  std::vector<float> range;             // metres; empty when the file has none
  // Organized clouds (height > 1) store rows = rings, columns = firing order.
  int width = 0;
  int height = 1;

  size_t size() const { return points.size(); }
  bool HasIntensity() const { return !intensity.empty(); }
  bool HasRing() const { return !ring.empty(); }
  bool IsOrganized() const { return height > 1 && static_cast<size_t>(width) * height == size(); }
};

// Loads PCD (ascii, binary, binary_compressed), PLY (ascii, binary little/big endian) or KITTI
// .bin (float32 x y z intensity) by extension. x, y, z are required; `ring` may have any integer
// type. Points with NaN/inf coordinates are dropped (organized clouds keep their grid only when
// nothing was dropped). Throws IoError naming the file and the problem (missing file, truncated
// data, no x/y/z field, unsupported layout, no finite points).
LidarCloud LoadCloud(const std::filesystem::path& path);

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };
// Writes x y z [intensity] [ring (uint16)] [range]. Throws IoError on failure.
void SavePcd(const std::filesystem::path& path, const LidarCloud& cloud,
             PcdEncoding encoding = PcdEncoding::kBinary);
// Writes binary little-endian PLY with the same fields.
void SavePly(const std::filesystem::path& path, const LidarCloud& cloud);
// Writes KITTI .bin (x y z intensity as float32).
void SaveKittiBin(const std::filesystem::path& path, const LidarCloud& cloud);

}  // namespace calibench
