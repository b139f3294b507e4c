#include "core/io/load_limits.h"

#include "core/base/types.h"

namespace calibench {

bool LoadLimits::Check(std::string* why) const {
  if (max_cloud_points < 1 || max_image_pixels < 1 || max_depth_pixels < 1 || max_scan_points < 1) {
    *why = "every load limit must be at least 1";
    return false;
  }
  return true;
}

void CheckLoadLimit(const std::filesystem::path& file, const char* what, std::int64_t count,
                    std::int64_t limit, const char* option) {
  if (count <= limit) return;
  throw IoError(file.string() + ": " + what + " " + std::to_string(count) +
                " is over the limit of " + std::to_string(limit) + " (LoadLimits::" + option +
                "; no real sensor gives that many)");
}

}  // namespace calibench
