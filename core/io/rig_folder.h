// A rig's folder form: one LiDAR and several cameras, captured together.
//   clouds/<stem>.pcd            the LiDAR's sweep of capture <stem>
//   images/<camera>/<stem>.png   each camera's frame of it (a camera may miss a capture)
//   cameras/<camera>.yaml        each camera's intrinsics (any format LoadCameraFile reads)
//   target.json                  the board
// Each camera is then a dataset of its own (its pairs are the captures it has a frame of), so
// every single-camera step runs on it unchanged; the rig solve (core/lidar_camera/rig.h) joins
// them. The single-camera folder (camera.yaml, images/<stem>.png) is a rig of one camera.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/io/dataset.h"

namespace calibench {

struct RigFolder {
  std::filesystem::path folder;
  std::vector<std::string> camera_names;  // cameras/<name>.yaml, in natural order
  std::vector<Dataset> cameras;           // per camera: its intrinsics, the board, its pairs
};

// Whether `path` is a folder in the rig's form (it holds cameras/).
bool IsRigFolder(const std::filesystem::path& path);

// Reads the rig folder; throws IoError naming the folder or file and the problem (no cameras/,
// no target.json, a camera file that does not read, a camera without images/<camera>/ or
// without a capture, no clouds).
RigFolder LoadRigFolder(const std::filesystem::path& path);

}  // namespace calibench
