// The LRF controller's session lifecycle: opening a manifest (its session resumed, else its newest
// backup that opens, else moved aside) or a session file, the record mirrored into the rows,
// autosave, undo and redo. The record is the LRF job's (core/session/lrf_calibration_job.h).
#include <nlohmann/json.hpp>

#include "ui/lrf/controller.h"

namespace calibench::ui {
namespace {

// The session's selected pair (its view's "selected_pair"), or the first one.
int SelectedInView(const Session& session) {
  const nlohmann::json view = nlohmann::json::parse(session.view_json, nullptr, false);
  const auto found = view.is_object() ? view.find("selected_pair") : view.end();
  if (found != view.end() && found->is_string())
    for (size_t i = 0; i < session.pairs.size(); ++i)
      if (session.pairs[i].id == found->get<std::string>()) return static_cast<int>(i);
  return session.pairs.empty() ? -1 : 0;
}

}  // namespace

bool LrfController::Fail(const std::string& message) {
  std::lock_guard lock(mutex_);
  SetStatus(message, true);
  return false;
}

bool LrfController::Open(const std::filesystem::path& manifest, ExistingSession existing) {
  std::string why;
  std::shared_ptr<const LrfDataset> dataset;
  std::optional<Session> saved;
  OpenedSessionFile file;
  try {
    if (!options_.Check(&why)) throw IoError("LRF pipeline options: " + why);
    dataset = std::make_shared<const LrfDataset>(LoadLrfDataset(manifest));
    file = OpenSessionFileBeside(
        DefaultLrfSessionPath(dataset->manifest), existing, session_lock_,
        [&](const std::filesystem::path& candidate) {
          LrfSessionWithDataset opened = LoadLrfSessionWithDataset(candidate);
          if (opened.session.dataset != NormalizeSessionPath(dataset->manifest))
            throw IoError(candidate.string() + " is the session of " +
                          opened.session.dataset.string());
          saved = std::move(opened.session);
        });
  } catch (const IoError& e) {
    return Fail(std::string("cannot open: ") + e.what());
  }
  Start(dataset, std::move(saved), file.path, std::move(file.lock), file.note);
  return true;
}

bool LrfController::OpenSession(const std::filesystem::path& session_path) {
  std::string why, note;
  std::optional<FileLock> lock;
  LrfSessionWithDataset opened;
  try {
    if (!options_.Check(&why)) throw IoError("LRF pipeline options: " + why);
    lock = LockSessionFile(session_path, session_lock_, &note);
    opened = LoadLrfSessionWithDataset(session_path);
    note += std::string(note.empty() ? "" : "; ") + "opened the session " + session_path.string();
  } catch (const IoError& e) {
    return Fail(std::string("cannot open: ") + e.what());
  }
  Start(std::make_shared<const LrfDataset>(std::move(opened.dataset)), std::move(opened.session),
        session_path, std::move(lock), note);
  return true;
}

void LrfController::Start(std::shared_ptr<const LrfDataset> dataset, std::optional<Session> saved,
                          const std::filesystem::path& session_path, std::optional<FileLock> lock,
                          const std::string& note) {
  // Jobs of the previous dataset are dropped; one still running discards its result.
  worker_.DropQueued();
  const bool resolve = saved && saved->result.has_value();  // what was on screen: a solve
  // The job every front end runs; the worker alone drives its extraction and solve, each job of
  // the worker holding the one of its Open.
  auto job = std::make_shared<LrfCalibrationJob>(*dataset, options_, std::move(saved));
  std::uint64_t open_count;
  {
    std::lock_guard guard(mutex_);
    open_count = ++open_count_;
    if (lock)
      session_lock_ = std::move(lock);
    else if (!session_lock_ || session_lock_->locked() != session_path)
      session_lock_.reset();
    const std::uint64_t generation = state_.generation;
    state_ = LrfSnapshot{};
    state_.generation = generation;
    state_.manifest = dataset->manifest;
    state_.dataset = dataset;
    state_.session_path = session_path;
    state_.session_note = note;
    for (const LrfPairEntry& entry : dataset->pairs)
      state_.pairs.Edit().emplace_back().id = entry.id;
    state_.extracted_total = static_cast<int>(state_.pairs.size());
    outcome_.reset();
    job_ = job;
    job_->record().AutosaveTo(session_path);
    const Session session = job_->record().Current();
    state_.solver.method = *ParseLrfMethod(session.lrf_method);
    Restatus();
    state_.selected = SelectedInView(session);
    Autosave();
    SetStatus((note.empty() ? "" : note + "; ") + "extracting features of " +
                  std::to_string(state_.pairs.size()) + " pairs from " + dataset->manifest.string(),
              false);
  }
  for (int i = 0; i < static_cast<int>(dataset->pairs.size()); ++i)
    worker_.Enqueue([this, job, open_count, i] { Extract(job.get(), open_count, i); });
  if (dataset->target_type == LrfTargetType::kCheckerboard)
    worker_.Enqueue([this] { LoadSelectedImage(); });
  if (resolve) worker_.Enqueue([this] { Solve(); });  // the same features and word: the same solve
}

void LrfController::Autosave() { AutosaveRecord(job_ ? &job_->record() : nullptr); }

void LrfController::AfterEdit() {
  mutex_.AssertHeld(__func__);
  state_.can_undo = job_->record().CanUndo();
  state_.can_redo = job_->record().CanRedo();
  Autosave();
  ++state_.generation;
}

void LrfController::Handle(const LrfUndo&) { Restore(job_->record().Undo(), "undid"); }
void LrfController::Handle(const LrfRedo&) { Restore(job_->record().Redo(), "redid"); }

void LrfController::Restore(const std::optional<Session>& restored, const char* what) {
  if (!restored) {
    SetStatus(std::string("nothing to ") + (what[0] == 'u' ? "undo" : "redo"), false);
    return;
  }
  state_.solver.method = *ParseLrfMethod(restored->lrf_method);
  Restatus();
  Autosave();
  // The solve shown is the restored state's: solved again from its word (the same features give
  // the same solve), or none when that state had none.
  if (restored->result) {
    state_.solver.running = true;
    worker_.Enqueue([this] { Solve(); });
  } else {
    const LrfMethod method = state_.solver.method;
    state_.solver = LrfSolverView{};
    state_.solver.method = method;
    outcome_.reset();
    UpdatePairFigures();
  }
  SetStatus(std::string(what) + " the last change", false);
}

}  // namespace calibench::ui
