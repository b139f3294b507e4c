// What the workbench's file browser lists: the entries of a folder a user can open or walk
// into. No ImGui here.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace calibench::ui {

enum class EntryKind {
  kFolder,         // a plain folder: walk into it
  kDatasetFolder,  // clouds/ + images/ (+ camera.yaml, target.json) or a dataset.json inside
  kRosbag2Folder,  // a rosbag2 recording (metadata.yaml beside its .db3 / .mcap files)
  kRecording,      // .bag, .db3, .mcap
  kJson,           // a dataset manifest or a session
};

struct FolderEntry {
  std::string name;
  EntryKind kind = EntryKind::kFolder;
  bool Openable() const { return kind != EntryKind::kFolder; }
  bool IsFolder() const {
    return kind == EntryKind::kFolder || kind == EntryKind::kDatasetFolder ||
           kind == EntryKind::kRosbag2Folder;
  }
};

// Sub-folders first, then files, each in natural order (pose2 before pose10); hidden entries
// (a leading dot) and files of other kinds left out. Throws IoError naming the folder when it
// cannot be read.
std::vector<FolderEntry> ListFolder(const std::filesystem::path& folder);

// A short word for the kind, shown beside the name ("dataset", "recording", ...).
const char* EntryKindLabel(EntryKind kind);

}  // namespace calibench::ui
