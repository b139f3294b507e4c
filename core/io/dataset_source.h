// What a `--dataset` path is, recognised by its content rather than its name: the one resolver
// every command and the workbench open datasets through (docs/architecture.md, "Conventions and
// file contracts").
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace calibench {

enum class DatasetKind {
  kLidarCamera,  // calibench.dataset.v1, or the folder form (clouds/, images/, camera.yaml, ...)
  kLrf,          // calibench.lrf-dataset.v1
  kRecording,    // a ROS 1 .bag, an MCAP, a rosbag2 .db3 or folder
};
std::string DatasetKindName(DatasetKind kind);  // "LiDAR-camera dataset", "LRF dataset", ...

struct DatasetSource {
  DatasetKind kind = DatasetKind::kLidarCamera;
  // The manifest to read; for the folder form and recordings, the path given.
  std::filesystem::path path;
  bool folder_form = false;  // kLidarCamera without a manifest
};

// A manifest is recognised by its "format" field, whatever its name; a folder by the manifest it
// holds (dataset.json, then manifest.json, then the one other *.json whose format is a dataset's),
// by the folder form, or as a rosbag2 recording; a file by its first bytes as a recording.
// nullopt with *why (naming the path and listing what was looked for) when nothing fits.
std::optional<DatasetSource> RecogniseDataset(const std::filesystem::path& path, std::string* why);

// RecogniseDataset, and the kind a command needs: throws IoError naming the path otherwise,
// saying what it is and which command opens it. A file that is neither a manifest nor a
// recording is returned as `wanted`, for its loader to name the problem precisely.
DatasetSource ResolveDataset(const std::filesystem::path& path, DatasetKind wanted);

}  // namespace calibench
