// Builds a calibench.dataset.v1 manifest for ../shared/datasets/acfr-vlp16-chessboard (real
// VLP-16 + fisheye camera, 40 chessboard pairs) without copying its files.
#pragma once

#include <filesystem>

#include "core/base/types.h"

namespace calibench::test {

// The authors' reference extrinsic (mean of their 50 estimates), as cam_from_lidar.
Pose AcfrReferenceCamFromLidar();

// Writes `out_dir/dataset.json` pointing at the shared files (absolute paths). Each pair is
// seeded from the LiDAR-frame board centre the authors' tool extracted (poses.csv row 7, in mm),
// with `seed_radius_m` (0.25 m: larger radii pull in the board's edge returns and the tripod).
// Throws IoError when poses.csv is missing or malformed.
std::filesystem::path WriteAcfrManifest(const std::filesystem::path& dataset_dir,
                                        const std::filesystem::path& out_dir,
                                        double seed_radius_m = 0.25);

// The ACFR files as a user lays them out: clouds/, images/, camera.yaml, target.json (with the
// sheet size), no seeds anywhere. Links, not copies; `dir` is emptied first.
std::filesystem::path WriteAcfrFolder(const std::filesystem::path& acfr,
                                      const std::filesystem::path& dir);

}  // namespace calibench::test
