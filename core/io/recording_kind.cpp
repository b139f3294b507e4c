#include "core/io/recording_kind.h"

#include <array>
#include <fstream>
#include <string_view>

namespace calibench {

namespace fs = std::filesystem;

RecordingKind SniffRecording(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return RecordingKind::kNone;
  std::ifstream in(path, std::ios::binary);
  std::array<char, 16> head{};
  in.read(head.data(), head.size());
  const std::string_view bytes(head.data(), static_cast<std::size_t>(in.gcount()));
  if (bytes.starts_with("#ROSBAG V")) return RecordingKind::kRos1;
  if (bytes.starts_with("\x89MCAP")) return RecordingKind::kMcap;
  if (bytes.starts_with(std::string_view("SQLite format 3\0", 16))) return RecordingKind::kSqlite;
  return RecordingKind::kNone;
}

bool LooksLikeBag(const fs::path& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return fs::exists(path / "metadata.yaml", error);
  return SniffRecording(path) != RecordingKind::kNone;
}

}  // namespace calibench
