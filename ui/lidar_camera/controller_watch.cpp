// The controller's live side: solving by itself after every change, a followed capture's pairs
// joining the list as they land (the following itself is FollowTask's,
// ui/lidar_camera/follow_task.h), and after every solve `advise`'s pre-flight findings and next
// pose (the ghost board), with whether the newest pair matched the ghost.
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

void Controller::SetAutoSolve(bool on) {
  std::lock_guard lock(mutex_);
  state_.auto_solve = on;
  ++state_.generation;
}

void Controller::RequestSolve() {
  mutex_.AssertHeld(__func__);
  if (!state_.auto_solve || solve_queued_ || !state_.dataset) return;
  solve_queued_ = true;
  worker_.Enqueue([this] {
    {
      std::lock_guard lock(mutex_);
      solve_queued_ = false;
    }
    Solve(/*asked=*/false);
  });
}

void Controller::Follow(const CaptureFollowRequest& request) { follow_.Start(request); }

void Controller::StopWatching() { follow_.Stop(); }

void Controller::WatchFolder(const std::filesystem::path& folder, FolderWatchOptions options) {
  CaptureFollowRequest request;
  request.source = std::filesystem::absolute(folder).string();
  request.folder = options;
  Follow(request);
}

void Controller::WatchRecording(const std::filesystem::path& recording,
                                const std::filesystem::path& out, std::optional<BoardSpec> board,
                                BagImportOptions options) {
  CaptureFollowRequest request;
  request.source = std::filesystem::absolute(recording).string();
  request.out = out;
  request.board = std::move(board);
  request.import = std::move(options);
  Follow(request);
}

bool Controller::ResumeGrownCapture(Dataset dataset) {
  const std::filesystem::path session_path = dataset.manifest / "calibench.session.json";
  std::error_code error;
  if (!std::filesystem::exists(session_path, error)) return false;
  Session saved;
  try {
    saved = LoadSession(session_path);
  } catch (const IoError&) {
    return false;  // the usual resume says why and keeps it as a backup
  }
  const size_t known = saved.pairs.size();
  if (known > dataset.pairs.size() ||
      !std::filesystem::equivalent(saved.dataset, dataset.manifest, error))
    return false;
  for (size_t i = 0; i < known; ++i)
    if (saved.pairs[i].id != dataset.pairs[i].id) return false;
  dataset.pairs.resize(known);
  std::string note;
  std::optional<FileLock> lock = LockSession(session_path, &note);  // throws: open elsewhere
  Open(dataset, std::move(saved), session_path,
       "resumed the session in " + session_path.string() + " (" + std::to_string(known) +
           " pairs; the ones written since join as new)" + (note.empty() ? "" : "; " + note),
       std::move(lock));
  return true;
}

void Controller::OnLivePairLoaded(int index) {
  mutex_.AssertHeld(__func__);
  const PairView& pair = state_.pairs.at(index);
  // The views move to the newest pair once it is loaded (not before: they would show nothing
  // meanwhile), unless the user looks at an older one.
  if (FollowsTo(index)) {
    state_.selected = index;
    state_.reprojection.reset();  // the last image stays up until this one's is decoded
    worker_.Enqueue([this] { EnsureSelectedImage(); });
    worker_.Enqueue([this, index] { ComputeReprojection(index); });
  }
  // The newest pair against the ghost board that was shown while it was taken.
  if (pair.camera && state_.next_pose && !state_.watching.empty()) {
    const SuggestionMatch match =
        MatchSuggestion(pair.camera->cam_from_board, *state_.next_pose, GuidanceOptions{});
    state_.ghost_match = "pair " + pair.id + " " + match.words;
    state_.ghost_matched = match.matches;
  }
}

void Controller::AddPair(const PairEntry& entry) {
  std::lock_guard lock(mutex_);
  if (!state_.dataset) return;
  for (const PairView& pair : state_.pairs)
    if (pair.id == entry.id) return;
  state_.dataset->pairs.push_back(entry);
  PairView view;
  view.id = entry.id;
  state_.pairs.Edit().push_back(std::move(view));
  if (job_) job_->record().AddPair(entry.id);
  ++state_.loading_total;
  const int index = static_cast<int>(state_.pairs.size()) - 1;
  ++state_.generation;
  worker_.Enqueue([this, index] { LoadPair(index); });  // selects it when it follows (FollowsTo)
}

}  // namespace calibench::ui
