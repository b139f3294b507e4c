// The features of the pairs a watch has detected, kept beside its session so that a watch killed
// and started again on the same capture does not detect them again. One JSON object per line,
// appended as pairs are detected or change (the last line of a pair counts); a line cut short by
// a kill is ignored, so the file stays usable whatever moment the process died. Each line records
// the size and modification time of the pair's two files: a pair whose files changed since is
// detected again.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "core/lidar_camera/pipeline.h"

namespace calibench {

// Appends pairs to the cache file (created when missing).
class FeatureCacheWriter {
 public:
  explicit FeatureCacheWriter(std::filesystem::path path);
  // Appends one line for the pair and flushes it to the file. Throws IoError naming the file.
  void Append(const PairEntry& entry, const PairFeatures& features);
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct CachedPair {
  PairEntry entry;  // the files the features came from
  PairFeatures features;
};
// The cached pairs by id, of those whose files are unchanged; lines that do not parse (cut short,
// or from another version) are skipped and counted in *skipped. A missing file is an empty cache.
std::map<std::string, CachedPair> LoadFeatureCache(const std::filesystem::path& path,
                                                   int* skipped = nullptr);

// Where a session's feature cache lives: beside it, "<session stem>.features.jsonl".
std::filesystem::path FeatureCachePath(const std::filesystem::path& session_path);

}  // namespace calibench
