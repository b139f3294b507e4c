#include "core/session/session_record.h"

#include <utility>

#include "core/results/pair_status.h"

namespace calibench {

const PairState* FindPair(const Session& session, const std::string& id) {
  for (const PairState& pair : session.pairs)
    if (pair.id == id) return &pair;
  return nullptr;
}

PairState* FindPair(Session* session, const std::string& id) {
  return const_cast<PairState*>(FindPair(*session, id));
}

void ForgetBrush(Session* session, const std::string& id) {
  if (PairState* pair = FindPair(session, id)) {
    pair->brush.reset();
    pair->brush_from_seed = false;
  }
}

SessionRecord::SessionRecord(Session session, std::size_t undo_depth)
    : session_(std::move(session)), history_(undo_depth) {
  history_.Reset(session_);
}

SessionRecord::SessionRecord(const SessionRecord& other) {
  std::lock_guard lock(other.mutex_);
  session_ = other.session_;
  history_ = other.history_;
}

Session SessionRecord::Current() const {
  std::lock_guard lock(mutex_);
  return session_;
}

std::optional<PairState> SessionRecord::Pair(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const PairState* pair = FindPair(session_, id);
  return pair ? std::optional(*pair) : std::nullopt;
}

PairEdit SessionRecord::EditOf(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const PairState* pair = FindPair(session_, id);
  return pair ? EditOfPair(*pair) : PairEdit{};
}

PairEdits SessionRecord::Edits() const {
  std::lock_guard lock(mutex_);
  return EditsFromSession(session_);
}

bool IsRejected(const Session& session, const std::string& id, std::string* reason) {
  const PairState* pair = FindPair(session, id);
  if (!pair || pair->status != PairStatus::kRejected) return false;
  if (reason) *reason = pair->reason.empty() ? kRejectedByUser : pair->reason;
  return true;
}

bool SessionRecord::Rejected(const std::string& id, std::string* reason) const {
  std::lock_guard lock(mutex_);
  return IsRejected(session_, id, reason);
}

void SessionRecord::ApplyOptions(PipelineOptions* options) const {
  std::lock_guard lock(mutex_);
  session_.settings.Apply(options);
}

void SessionRecord::Reset(Session session) {
  std::lock_guard lock(mutex_);
  session_ = std::move(session);
  history_.Reset(session_);
}

void SessionRecord::Commit(Session session, bool amend) {
  std::lock_guard lock(mutex_);
  session_ = std::move(session);
  Record(amend);
}

void SessionRecord::Edit(const std::function<void(Session*)>& change, bool amend) {
  std::lock_guard lock(mutex_);
  change(&session_);
  Record(amend);
}

void SessionRecord::Record(bool amend) {
  if (amend)
    history_.Amend(session_);
  else
    history_.Push(session_);
}

void SessionRecord::Adjust(const std::function<void(Session*)>& change) {
  std::lock_guard lock(mutex_);
  change(&session_);
}

void SessionRecord::AddPair(const std::string& id) {
  std::lock_guard lock(mutex_);
  if (FindPair(session_, id)) return;
  PairState pair;
  pair.id = id;
  session_.pairs.push_back(std::move(pair));
}

std::optional<Session> SessionRecord::Restore(std::optional<Session> restored) {
  if (!restored) return std::nullopt;
  // Pairs that joined since that step (a followed capture) stay as they are.
  for (const PairState& now : session_.pairs)
    if (!FindPair(*restored, now.id)) restored->pairs.push_back(now);
  session_ = *restored;
  return restored;
}

std::optional<Session> SessionRecord::Undo() {
  std::lock_guard lock(mutex_);
  return Restore(history_.Undo());
}

std::optional<Session> SessionRecord::Redo() {
  std::lock_guard lock(mutex_);
  return Restore(history_.Redo());
}

bool SessionRecord::CanUndo() const {
  std::lock_guard lock(mutex_);
  return history_.CanUndo();
}

bool SessionRecord::CanRedo() const {
  std::lock_guard lock(mutex_);
  return history_.CanRedo();
}

void SessionRecord::AutosaveTo(const std::filesystem::path& path) {
  std::lock_guard lock(mutex_);
  autosaver_ = path.empty() ? nullptr : std::make_unique<Autosaver>(path);
}

void SessionRecord::Autosave() {
  std::lock_guard lock(mutex_);
  if (autosaver_) autosaver_->Save(session_);
}

void SessionRecord::SaveAs(const std::filesystem::path& path) {
  std::lock_guard lock(mutex_);
  SaveSession(path, session_);
  autosaver_ = std::make_unique<Autosaver>(path);
}

}  // namespace calibench
