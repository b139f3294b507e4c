// The LRF controller's session lifecycle: opening a manifest (its session resumed, else its newest
// backup that opens, else moved aside) or a session file, the record shown in the rows, undo and
// redo shown. The record is the LRF job's (core/session/lrf_calibration_job.h); its file, lock and
// autosave are EditedSession's (ui/state/session_opening.h).
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
    file =
        session_.OpenBeside(DefaultLrfSessionPath(dataset->manifest), existing,
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
    lock = session_.Lock(session_path, &note);
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
    const std::uint64_t generation = state_.generation;
    state_ = LrfSnapshot{};
    state_.generation = generation;
    state_.manifest = dataset->manifest;
    state_.dataset = dataset;
    state_.session_note = note;
    for (const LrfPairEntry& entry : dataset->pairs)
      state_.pairs.Edit().emplace_back().id = entry.id;
    state_.extracted_total = static_cast<int>(state_.pairs.size());
    outcome_.reset();
    job_ = job;
    session_.Attach(&job_->record(), session_path, std::move(lock));
    const Session session = job_->record().Current();
    state_.solver.method = *ParseLrfMethod(session.lrf_method);
    Restatus();
    state_.selected = SelectedInView(session);
    session_.Autosave();
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

void LrfController::Handle(const LrfUndo&) {
  if (std::optional<Session> restored = session_.Step(/*undo=*/true)) Restore(*restored, "undid");
}
void LrfController::Handle(const LrfRedo&) {
  if (std::optional<Session> restored = session_.Step(/*undo=*/false)) Restore(*restored, "redid");
}

void LrfController::Restore(const Session& restored, const char* what) {
  state_.solver.method = *ParseLrfMethod(restored.lrf_method);
  Restatus();
  session_.Autosave();
  // The solve shown is the restored state's: solved again from its word (the same features give
  // the same solve), or none when that state had none.
  if (restored.result) {
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
