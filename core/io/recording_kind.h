// Which recording container a path is, by its content: the first bytes of a file, or a rosbag2
// folder's metadata.yaml. A file format's fact, so below the readers (core/recording/bag.h opens
// what this recognises) and the dataset resolver (core/io/dataset_source.h) alike.
#pragma once

#include <filesystem>

namespace calibench {

enum class RecordingKind { kRos1, kMcap, kSqlite, kNone };

// The container a file starts like; kNone for a folder, a missing file or anything else.
RecordingKind SniffRecording(const std::filesystem::path& path);

// True when the file starts like a ROS 1 bag, an MCAP or an SQLite file, or the folder holds a
// rosbag2 metadata.yaml: for a drop onto the workbench. Never throws.
bool LooksLikeBag(const std::filesystem::path& path);

}  // namespace calibench
