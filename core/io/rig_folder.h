// A rig: one LiDAR and several cameras, captured together, in its folder form or its manifest.
// The folder form:
//   clouds/<stem>.pcd            the LiDAR's sweep of capture <stem>
//   images/<camera>/<stem>.png   each camera's frame of it (a camera may miss a capture)
//   cameras/<camera>.yaml        each camera's intrinsics (any format LoadCameraFile reads)
//   target.json                  the board
// Each camera is then a dataset of its own (its pairs are the captures it has a frame of), so
// every single-camera step runs on it unchanged; the rig solve (core/lidar_camera/rig.h) joins
// them. The single-camera folder (camera.yaml, images/<stem>.png) is a rig of one camera.
// The manifest form (calibench.dataset.v1 with "cameras" by name in place of "camera"):
//   "cameras": {"<camera>": {inline camera} | {"file": "cameras/front.yaml"}},
//   "pairs": [{"id", "cloud", "images": {"<camera>": "images/front/0000.png", ...},
//              "lidar_seed"?}],
//   "ground_truth": {"cameras": {"<camera>": {"cam_from_lidar": 4x4}}} (optional)
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/io/dataset.h"

namespace calibench {

struct RigFolder {
  std::filesystem::path folder;           // the folder, or the manifest file
  std::vector<std::string> camera_names;  // cameras/<name>.yaml, in natural order
  std::vector<Dataset> cameras;           // per camera: its intrinsics, the board, its pairs
};

// Whether `path` is a folder in the rig's form (it holds cameras/).
bool IsRigFolder(const std::filesystem::path& path);
// Whether `path` is a rig: a rig folder, or a manifest naming "cameras".
bool IsRig(const std::filesystem::path& path);

// Reads the rig folder; throws IoError naming the folder or file and the problem (no cameras/,
// no target.json, a camera file that does not read, a camera without images/<camera>/ or
// without a capture, no clouds).
RigFolder LoadRigFolder(const std::filesystem::path& path);
// A rig folder or a rig manifest; throws IoError naming the file and the problem (a manifest:
// the member, e.g. "pairs[3].images.left: camera 'left' is not in cameras").
RigFolder LoadRig(const std::filesystem::path& path);
// One camera of a rig as a single-camera dataset (Dataset::camera_name set, manifest the rig's
// path), what the workbench and a camera's session open. IoError naming the rig and its cameras
// when it has no camera of that name.
Dataset LoadRigCamera(const std::filesystem::path& path, const std::string& camera);
// A single camera's dataset as a rig of one (every camera belongs to a rig, as in COLMAP's rig
// model): the dataset's manifest for its folder, its one camera named after Dataset::camera_name,
// else "camera". The workbench sees every dataset this way; the rig's own solve, strip and meter
// rows need two cameras or more.
RigFolder RigOfOne(const Dataset& dataset);
// The index of `camera` in the rig; IoError naming the rig and its cameras when absent.
size_t RigCameraIndex(const RigFolder& rig, const std::string& camera);

}  // namespace calibench
