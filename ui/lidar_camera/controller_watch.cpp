// The controller's live side: auto-solve switched (the solving is SolveTask's), a followed capture
// started and stopped (the following itself is FollowTask's, ui/lidar_camera/follow_task.h; its
// pairs join as LoadingTask's) and, when it opens, the session an earlier watch left resumed.
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

void Controller::SetAutoSolve(bool on) {
  std::lock_guard lock(mutex_);
  state_.auto_solve = on;
  ++state_.generation;
}

void Controller::StopWatching() { follow_.Stop(); }

void Controller::WatchFolder(const std::filesystem::path& folder, FolderWatchOptions options) {
  CaptureFollowRequest request;
  request.source = std::filesystem::absolute(folder).string();
  request.folder = options;
  follow_.Start(request);
}

void Controller::WatchRecording(const std::filesystem::path& recording,
                                const std::filesystem::path& out, std::optional<BoardSpec> board,
                                BagImportOptions options) {
  CaptureFollowRequest request;
  request.source = std::filesystem::absolute(recording).string();
  request.out = out;
  request.board = std::move(board);
  request.import = std::move(options);
  follow_.Start(request);
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
  std::optional<FileLock> lock = session_.Lock(session_path, &note);  // throws: open elsewhere
  Open(dataset, std::move(saved), session_path,
       "resumed the session in " + session_path.string() + " (" + std::to_string(known) +
           " pairs; the ones written since join as new)" + (note.empty() ? "" : "; " + note),
       std::move(lock));
  return true;
}

}  // namespace calibench::ui
