// assets/: the files Calibench ships beside its binary (target presets, LiDAR presets, the
// report's template, the workbench's layout). Found at run time relative to the executable, so
// an installed calibench works from any working directory.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace calibench {

// The places looked in, in order: $CALIBENCH_ASSETS; <exe dir>/../share/calibench/assets
// (`cmake --install`); <exe dir>/assets; the source tree's assets/ (a build tree's binary).
std::vector<std::filesystem::path> AssetSearchPath();

// The first of AssetSearchPath() holding `relative` (e.g. "report/report.html"): the full path
// of that file or folder. Throws IoError naming `relative` and every place looked in.
std::filesystem::path FindAsset(const std::filesystem::path& relative);

}  // namespace calibench
