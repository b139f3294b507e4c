// Sizes no real sensor reaches. A file that declares more (in its header, before anything is
// decoded or allocated) is refused with a message naming the file, the number and the limit,
// instead of taking the machine's memory: a 540 KB PNG can declare 16000 x 16000 pixels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace calibench {

struct LoadLimits {
  // Points per cloud file. The densest single sweeps (Ouster OS2-128 at 2048, Hesai AT128) hold
  // about 260k points; a few seconds of an accumulating Livox about 2.5 million.
  std::int64_t max_cloud_points = 5'000'000;
  // Camera image pixels: 8000 x 6000 (48 MP) passes, 16000 x 16000 does not.
  std::int64_t max_image_pixels = 100'000'000;
  // Depth image pixels: depth cameras give at most 1280 x 800; 4096 x 4096 is the limit.
  std::int64_t max_depth_pixels = 4096 * 4096;
  // Rays per 2D laser scan: real rangefinders give at most a few thousand (SICK LMS: 2161).
  std::int64_t max_scan_points = 100'000;

  bool Check(std::string* why) const;
};

// Throws IoError "<file>: <what> <count> is over the limit of <limit> (<option>)" when
// count > limit.
void CheckLoadLimit(const std::filesystem::path& file, const char* what, std::int64_t count,
                    std::int64_t limit, const char* option);

}  // namespace calibench
