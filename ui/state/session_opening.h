// How both workbenches open the session file of a dataset they open: one enum for what to do with
// a session already there, one function that locks, resumes (or its newest autosave backup that
// loads) or moves it aside, and says what it did. The session's own reading is the caller's
// (`load`): a LiDAR-camera session and an LRF session check different things. No GL, no ImGui.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "core/base/file_lock.h"

namespace calibench::ui {

// What to do when the dataset's session file already holds a session:
enum class ExistingSession {
  kReplace,     // start a new one over it (headless renders and tests, which own their files)
  kResume,      // open it instead (the window: an hour of someone's edits is never overwritten)
  kStartFresh,  // move it to `<session>.<date-time>.bak` first and say where, then a new one
  kInMemory,    // leave any session file alone and never write one (render draws; it does not edit)
};

struct OpenedSessionFile {
  std::filesystem::path path;    // the session file edited from now on; empty: in memory
  std::optional<FileLock> lock;  // held while it is open (none where no lock file can be made)
  bool resumed = false;          // `load` read the file that stands (or a backup of it)
  std::string note;              // what happened, in the status line's words
};

// The session file `path` for a dataset being opened, as `existing` says. Under kResume and
// kStartFresh a file that exists is tried with `load` (ResumeSessionBeside: the file, then its
// backups newest first; one that does not load, or kStartFresh, is moved aside). `held` is the
// workbench's own lock (kept when it is that file's). Throws IoError when another workbench has
// the file open or it cannot be moved aside.
OpenedSessionFile OpenSessionFileBeside(
    const std::filesystem::path& path, ExistingSession existing,
    const std::optional<FileLock>& held,
    const std::function<void(const std::filesystem::path&)>& load);

}  // namespace calibench::ui
