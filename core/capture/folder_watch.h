// A folder in the folder form (clouds/, images/, camera.yaml, target.json) that a capture is still
// filling: which pairs have become complete since the last look, which wait for a partner too
// long, and which files went away. Polling, so that it works on every file system (network and
// container mounts included) without inotify.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/io/dataset.h"

namespace calibench {

struct FolderWatchOptions {
  // A file counts as written when its size and modification time have not changed for this long
  // (a capture script writing in pieces), seconds. A file renamed into place from `.part` (or any
  // name the folder form ignores) is final at once.
  double settle_s = 0.3;
  // A stem whose cloud (image) has been written for this long without its image (cloud) is
  // reported once as incomplete, seconds; it still completes if the partner arrives later.
  double partner_timeout_s = 10.0;
  bool Check(std::string* why) const;
};

struct FolderEvent {
  enum class Kind {
    kPairComplete,  // both files written: `pair` is ready to be read
    kIncomplete,    // one file written, the other missing past partner_timeout_s
    kRemoved,       // a file seen before is gone
  };
  Kind kind = Kind::kPairComplete;
  std::string stem;
  PairEntry pair;      // kPairComplete
  std::string reason;  // kIncomplete, kRemoved: in words, naming the file
};

// Files that are not (yet) part of the folder form: hidden files, `.part`, `.tmp`, `~` backups.
bool IsTemporaryFileName(const std::filesystem::path& name);

class GrowingFolder {
 public:
  explicit GrowingFolder(std::filesystem::path folder, FolderWatchOptions options = {});
  // Looks at clouds/ and images/ at time now_s (seconds on any monotonic clock) and returns what
  // happened since the last look: pairs completed in the order their last file settled (stems in
  // natural order within one look), then incomplete stems, then removals. A missing clouds/ or
  // images/ folder is an empty one (the capture has not started).
  std::vector<FolderEvent> Poll(double now_s);
  // Stems already returned as complete (never returned again, even when rewritten).
  const std::set<std::string>& completed() const { return completed_; }
  // Marks stems as completed without returning them (a resumed watch).
  void MarkCompleted(const std::set<std::string>& stems);
  const std::filesystem::path& folder() const { return folder_; }

 private:
  struct FileState {
    std::filesystem::path path;
    std::uintmax_t size = 0;
    std::int64_t mtime_ns = 0;
    double changed_s = 0.0;  // when this size and time were first seen
    bool settled = false;
    double settled_s = 0.0;
  };
  // clouds/ or images/ listed into `files` (by stem), removals appended to `events`.
  void Scan(const char* sub, double now_s, std::map<std::string, FileState>* files,
            std::vector<FolderEvent>* events);

  std::filesystem::path folder_;
  FolderWatchOptions options_;
  std::map<std::string, FileState> clouds_, images_;
  std::set<std::string> completed_;
  std::set<std::string> reported_incomplete_;
  // Per subfolder: the final names of the temporary files seen at the last look.
  std::map<std::string, std::set<std::string>> temporaries_;
};

}  // namespace calibench
