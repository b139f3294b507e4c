#include "ui/state/folder_listing.h"

#include <algorithm>

#include "core/base/names.h"
#include "core/base/types.h"
#include "core/io/dataset_source.h"

namespace calibench::ui {
namespace fs = std::filesystem;

namespace {

// By content, as `--dataset` recognises it (a manifest of any name, the folder form, rosbag2).
EntryKind FolderKind(const fs::path& folder) {
  std::string ignored;
  const auto source = RecogniseDataset(folder, &ignored);
  if (!source) return EntryKind::kFolder;
  return source->kind == DatasetKind::kRecording ? EntryKind::kRosbag2Folder
                                                 : EntryKind::kDatasetFolder;
}

bool IsRecording(const std::string& extension) {
  return extension == ".bag" || extension == ".db3" || extension == ".mcap";
}

}  // namespace

std::vector<FolderEntry> ListFolder(const fs::path& folder) {
  std::error_code error;
  fs::directory_iterator it(folder, fs::directory_options::skip_permission_denied, error);
  if (error) throw IoError(folder.string() + ": cannot list the folder: " + error.message());
  std::vector<FolderEntry> entries;
  for (; it != fs::directory_iterator(); it.increment(error)) {
    if (error) break;
    const std::string name = it->path().filename().string();
    if (name.empty() || name.front() == '.') continue;
    std::error_code kind_error;
    if (it->is_directory(kind_error)) {
      entries.push_back({name, FolderKind(it->path())});
    } else if (it->is_regular_file(kind_error)) {
      const std::string extension = it->path().extension().string();
      if (IsRecording(extension)) entries.push_back({name, EntryKind::kRecording});
      if (extension == ".json") entries.push_back({name, EntryKind::kJson});
    }
  }
  if (error) throw IoError(folder.string() + ": cannot list the folder: " + error.message());
  std::sort(entries.begin(), entries.end(), [](const FolderEntry& a, const FolderEntry& b) {
    if (a.IsFolder() != b.IsFolder()) return a.IsFolder();
    return NaturalLess(a.name, b.name);
  });
  return entries;
}

const char* EntryKindLabel(EntryKind kind) {
  switch (kind) {
    case EntryKind::kFolder:
      return "folder";
    case EntryKind::kDatasetFolder:
      return "dataset";
    case EntryKind::kRosbag2Folder:
      return "rosbag2";
    case EntryKind::kRecording:
      return "recording";
    case EntryKind::kJson:
      return "json";
  }
  return "";
}

}  // namespace calibench::ui
