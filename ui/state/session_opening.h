// The session a workbench has open, the same for both workbenches: one enum for what to do with a
// session already beside a dataset, one function that locks, resumes (or its newest autosave
// backup that loads) or moves it aside and says what it did, and EditedSession, which owns the
// open session's file, its lock and its record's autosave, undo and redo. The session's own
// reading is the caller's (`load`): a LiDAR-camera session and an LRF session check different
// things. No GL, no ImGui.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "core/base/file_lock.h"
#include "core/session/session_record.h"
#include "ui/state/controller_state.h"

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

// The session a controller has open (one field of each workbench's controller): the record it
// edits (its job's, core/session/session_record.h), the file that record autosaves to and the
// lock held on it. Opening asks it (OpenBeside, Lock) and hands it the new job's record (Attach);
// every edit ends with Edited() (the undo buttons, the autosave, a new generation); undo and redo
// step its record (Step). All but OpenBeside and Lock with the controller's mutex held.
template <typename Snapshot>
class EditedSession {
 public:
  explicit EditedSession(TaskHost<Snapshot> host) : host_(host) {}

  // The dataset's session file `path` as `existing` says (OpenSessionFileBeside), the lock held
  // here kept when it is that file's.
  OpenedSessionFile OpenBeside(
      const std::filesystem::path& path, ExistingSession existing,
      const std::function<void(const std::filesystem::path&)>& load) const {
    return OpenSessionFileBeside(path, existing, lock_, load);
  }
  // A session file the user named, locked for this workbench (LockSessionFile): throws IoError
  // naming the process that has it open.
  std::optional<FileLock> Lock(const std::filesystem::path& path, std::string* note) const {
    return LockSessionFile(path, lock_, note);
  }

  // Opened: `record` (the new job's, living until the next Attach) autosaves to `path` (empty:
  // nowhere, in memory); `lock` is held from now on, else the lock held is dropped unless it is
  // `path`'s.
  void Attach(SessionRecord* record, const std::filesystem::path& path,
              std::optional<FileLock> lock) {
    host_.mutex.AssertHeld(__func__);
    if (lock)
      lock_ = std::move(lock);
    else if (path.empty() || !lock_ || lock_->locked() != path)
      lock_.reset();
    record_ = record;
    record_->AutosaveTo(path);
    host_.state.session_path = path;
    Undoable();
  }
  // After every edit of the record: the undo buttons, the autosave, a new generation.
  void Edited() {
    host_.mutex.AssertHeld(__func__);
    Undoable();
    Autosave();
    ++host_.state.generation;
  }
  // Writes the record's autosave when it has a file; a failure shows on the status line and in
  // save_error and is retried at the next edit.
  void Autosave() {
    host_.mutex.AssertHeld(__func__);
    try {
      if (record_) record_->Autosave();
      host_.state.save_error.clear();
    } catch (const IoError& e) {
      host_.state.save_error = e.what();
      host_.SetStatus(std::string("autosave failed: ") + e.what(), true);
    }
  }
  // Save as: the record written to `path` (locked first), which it autosaves to from now on; a
  // failure (another workbench has it open, it cannot be written) shows and changes nothing.
  void SaveAs(const std::filesystem::path& path) {
    host_.mutex.AssertHeld(__func__);
    try {
      std::string note;
      std::optional<FileLock> lock = Lock(path, &note);  // throws when another has it open
      if (!record_) throw IoError("no session to save: open a dataset first");
      record_->SaveAs(path);
      if (lock) lock_ = std::move(lock);
      host_.state.session_path = path;
      host_.state.save_error.clear();
      host_.SetStatus("saved session " + path.string(), false);
    } catch (const IoError& e) {
      host_.state.save_error = e.what();
      host_.SetStatus(e.what(), true);
    }
  }
  // One step back (`undo`) or forward in the record's history: the session as it stands there,
  // the undo buttons updated; none at either end (the status line says so).
  std::optional<Session> Step(bool undo) {
    host_.mutex.AssertHeld(__func__);
    std::optional<Session> restored;
    if (record_) restored = undo ? record_->Undo() : record_->Redo();
    if (!restored) host_.SetStatus(undo ? "nothing to undo" : "nothing to redo", false);
    Undoable();
    return restored;
  }

 private:
  void Undoable() {
    host_.state.can_undo = record_ && record_->CanUndo();
    host_.state.can_redo = record_ && record_->CanRedo();
  }

  TaskHost<Snapshot> host_;
  SessionRecord* record_ = nullptr;  // the open job's (none before a dataset opens)
  std::optional<FileLock> lock_;     // held while the session file is open for editing here
};

}  // namespace calibench::ui
