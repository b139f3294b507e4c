// The one record of a calibration session: the Session as its file keeps it — the user's word on
// each pair (a painted brush, a rejection and its reason), the solver settings, what the views
// showed, the last solve — with its undo history and, when it has a file, its autosave.
//
// The calibration job (calibration_job.h) owns it and reads the user's word from it at every
// detection and solve, so no front end copies its decisions into the job. A front end edits it
// from its own thread (the workbench's UI thread, while the job works on the worker): every member
// takes the record's own lock and releases it before returning, and nothing else is called while
// it is held (docs/architecture.md, "Threads").
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/session/session.h"

namespace calibench {

// Pair `id`'s state in `session`, or null; and its brush forgotten (painted or from a seed).
PairState* FindPair(Session* session, const std::string& id);
const PairState* FindPair(const Session& session, const std::string& id);
// Whether pair `id` is rejected in `session`; *reason (optional) gets the reason shown for it
// (kRejectedByUser when none was given).
bool IsRejected(const Session& session, const std::string& id, std::string* reason = nullptr);
void ForgetBrush(Session* session, const std::string& id);

class SessionRecord {
 public:
  explicit SessionRecord(Session session = {}, std::size_t undo_depth = 100);
  // A copy (a job copied to try a step on it) holds the same session and undo history but no
  // autosave file: two records never write one file.
  SessionRecord(const SessionRecord& other);
  SessionRecord& operator=(const SessionRecord&) = delete;

  Session Current() const;
  // Pair `id`'s state; nullopt when the record has no such pair.
  std::optional<PairState> Pair(const std::string& id) const;
  // The user's word on pair `id` as the pipeline takes it (EditsFromSession's: a painted brush,
  // not one pictured from a seed; a rejection), and on every pair.
  PairEdit EditOf(const std::string& id) const;
  PairEdits Edits() const;
  // Whether the user rejected pair `id`; *reason (optional) gets the reason shown for it.
  bool Rejected(const std::string& id, std::string* reason = nullptr) const;
  // The record's solver and RANSAC settings onto `options` (JobSettings::Apply).
  void ApplyOptions(PipelineOptions* options) const;

  // `session` becomes the record with nothing to undo: a session opened or resumed.
  void Reset(Session session);
  // An edit: `session` becomes the record and one undo step; with `amend` it replaces the current
  // step instead (the later dabs of one brush stroke, the solve it caused, the pair selected;
  // SessionHistory::Amend). A state equal to the record adds no step.
  void Commit(Session session, bool amend = false);
  // The same for a change to the record as it is now. `change` runs under the record's lock and
  // must not call the record.
  void Edit(const std::function<void(Session*)>& change, bool amend = false);
  // A change that is nobody's edit and no undo step: a pair that joined a growing capture, a
  // saved brush that does not fit its pair's cloud. `change` runs under the lock, as for Edit.
  void Adjust(const std::function<void(Session*)>& change);
  // Pair `id` as pending (no undo step), unless the record has it already.
  void AddPair(const std::string& id);

  // The state to restore, which becomes the record, or nullopt when there is none. Pairs that
  // joined since that step (a followed capture) keep their state as it is now.
  std::optional<Session> Undo();
  std::optional<Session> Redo();
  bool CanUndo() const;
  bool CanRedo() const;

  // Autosave to `path` from now on (empty: none); Autosaver's backups and atomic writes.
  void AutosaveTo(const std::filesystem::path& path);
  // Writes the record to its file when it changed since the last write (none without a file).
  // Throws IoError naming the file; a failed write is retried at the next call.
  void Autosave();
  // Writes the record to `path` now (atomically), which then becomes its autosave file.
  void SaveAs(const std::filesystem::path& path);

 private:
  std::optional<Session> Restore(std::optional<Session> restored);  // lock held
  void Record(bool amend);  // session_ as a new undo step, or amending the current one (lock held)

  mutable std::mutex mutex_;
  Session session_;
  SessionHistory history_;
  std::unique_ptr<Autosaver> autosaver_;
};

}  // namespace calibench
