// FindAsset: the executable's own location first, never the working directory.
#include "core/io/assets.h"

#include <cstdlib>
#include <system_error>

#include "core/base/types.h"

namespace calibench {

namespace fs = std::filesystem;

std::vector<fs::path> AssetSearchPath() {
  std::vector<fs::path> places;
  if (const char* env = std::getenv("CALIBENCH_ASSETS"); env && *env) places.emplace_back(env);
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    places.push_back(exe.parent_path().parent_path() / "share" / "calibench" / "assets");
    places.push_back(exe.parent_path() / "assets");
  }
#ifdef CALIBENCH_SOURCE_ASSETS
  places.emplace_back(CALIBENCH_SOURCE_ASSETS);
#endif
  return places;
}

fs::path FindAsset(const fs::path& relative) {
  std::string looked;
  for (const fs::path& place : AssetSearchPath()) {
    std::error_code error;
    if (fs::exists(place / relative, error)) return place / relative;
    looked += (looked.empty() ? "" : ", ") + (place / relative).string();
  }
  throw IoError("cannot find Calibench's asset '" + relative.string() + "' (looked in " + looked +
                "); reinstall, or point CALIBENCH_ASSETS at the assets/ folder");
}

}  // namespace calibench
