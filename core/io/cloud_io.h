// Point cloud files: PCD (ascii, binary, binary_compressed), PLY and KITTI .bin.
#pragma once

#include <filesystem>

#include "core/io/load_limits.h"
#include "core/lidar/cloud.h"

namespace calibench {

// Loads PCD (ascii, binary, binary_compressed), PLY (ascii, binary little/big endian) or KITTI
// .bin (float32 x y z intensity) by extension. x, y, z are required; `ring` may have any integer
// type. Points with NaN/inf coordinates are dropped (organized clouds keep their grid only when
// nothing was dropped). Throws IoError naming the file and the problem (missing file, truncated
// data, no x/y/z field, unsupported layout, no finite points, more points declared than
// limits.max_cloud_points: refused from the header, before the points are read).
LidarCloud LoadCloud(const std::filesystem::path& path, const LoadLimits& limits = {});

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };
// Writes x y z [intensity] [ring (uint16)] [range]. Throws IoError on failure.
void SavePcd(const std::filesystem::path& path, const LidarCloud& cloud,
             PcdEncoding encoding = PcdEncoding::kBinary);
// Writes binary little-endian PLY with the same fields.
void SavePly(const std::filesystem::path& path, const LidarCloud& cloud);
// Writes KITTI .bin (x y z intensity as float32).
void SaveKittiBin(const std::filesystem::path& path, const LidarCloud& cloud);

}  // namespace calibench
