// The controller's live side: solving by itself after every change, following a folder that a
// capture fills (pairs join the list as they land), and after every solve `advise`'s pre-flight
// findings and next pose (the ghost board), with whether the newest pair matched the ghost.
#include <chrono>
#include <functional>
#include <set>

#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr auto kPollPeriod = std::chrono::milliseconds(200);

// Whether clouds/ and images/ share a stem (the folder form has a pair to load).
bool HasFolderPairs(const std::filesystem::path& folder) {
  std::error_code error;
  std::set<std::string> clouds;
  for (const auto& entry : std::filesystem::directory_iterator(folder / "clouds", error))
    clouds.insert(entry.path().stem().string());
  for (const auto& entry : std::filesystem::directory_iterator(folder / "images", error))
    if (clouds.count(entry.path().stem().string())) return true;
  return false;
}

}  // namespace

void Controller::SetAutoSolve(bool on) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto_solve_ = on;
  state_.auto_solve = on;
  ++state_.generation;
}

void Controller::RequestSolve() {
  if (!auto_solve_ || solve_queued_ || !state_.dataset) return;
  solve_queued_ = true;
  worker_.Enqueue([this] {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      solve_queued_ = false;
    }
    Solve();
  });
}

void Controller::Follow(const std::filesystem::path& source, std::function<void()> loop) {
  StopWatching();
  stop_watch_ = false;
  // Pairs land while the user looks: the window's frames before the pairs' processing.
  worker_.LowerPriority();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    watching_ = std::filesystem::absolute(source);
    state_.watching = watching_;
  }
  watch_thread_ = std::thread(std::move(loop));
}

void Controller::WatchFolder(const std::filesystem::path& folder, FolderWatchOptions options) {
  Follow(folder, [this, options, folder = std::filesystem::absolute(folder)] {
    WatchLoop(folder, options);
  });
}

void Controller::WatchRecording(const std::filesystem::path& recording,
                                const std::filesystem::path& out, std::optional<BoardSpec> board,
                                BagImportOptions options) {
  options.max_pairs = 0;  // a capture has no cap: every hold is a pair
  Follow(recording, [this, recording = std::filesystem::absolute(recording), out, board, options] {
    std::error_code error;
    std::filesystem::create_directories(out, error);
    GrowingRecording growing(recording, out, board, options);
    WatchRecordingLoop(&growing);
  });
}

void Controller::WatchRecordingLoop(GrowingRecording* recording) {
  bool opened = false;
  while (!stop_watch_) {
    RecordingUpdate update;
    try {
      update = recording->Poll();
    } catch (const IoError& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      SetStatus(std::string("cannot watch: ") + e.what(), true);
      return;
    }
    if (!update.notes.empty()) {
      std::lock_guard<std::mutex> lock(mutex_);
      SetStatus(update.notes.back(), false);
    }
    // The dataset folder opens with the first pair: the recording tells its camera and board.
    if (!opened && !update.pairs.empty()) {
      try {
        OpenLoadedDataset(*recording->Setup(), {}, ExistingSession::kResume);
      } catch (const IoError& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        SetStatus(std::string("cannot watch: ") + e.what(), true);
        return;
      }
      opened = true;
    }
    for (const PairEntry& pair : update.pairs) AddPair(pair);
    if (update.closed) {
      std::lock_guard<std::mutex> lock(mutex_);
      SetStatus("the recording was closed by its recorder; its " +
                    std::to_string(state_.pairs.size()) + " pairs are in " +
                    recording->OutDir().string(),
                false);
      return;
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
}

void Controller::StopWatching() {
  stop_watch_ = true;
  if (watch_thread_.joinable()) watch_thread_.join();
}

void Controller::WatchLoop(std::filesystem::path folder, FolderWatchOptions options) {
  // The capture's camera and target first (a capture script may write them after starting).
  bool said = false;
  for (;;) {
    if (stop_watch_) return;
    std::error_code error;
    if (std::filesystem::exists(folder / "camera.yaml", error) &&
        std::filesystem::exists(folder / "target.json", error))
      break;
    if (!said) {
      std::lock_guard<std::mutex> lock(mutex_);
      SetStatus("watching " + folder.string() + ": waiting for camera.yaml and target.json", false);
      said = true;
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
  try {
    // The pairs already there, and the session of an earlier watch, resumed; before the first
    // pair lands, the camera and the target alone.
    Dataset dataset = LoadFolderSetup(folder);
    if (HasFolderPairs(folder)) dataset = LoadDataset(folder);
    dataset.manifest = folder;
    if (!ResumeGrownCapture(dataset)) OpenLoadedDataset(dataset, {}, ExistingSession::kResume);
  } catch (const IoError& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    SetStatus(std::string("cannot watch: ") + e.what(), true);
    return;
  }
  GrowingFolder growing(folder, options);
  {
    std::set<std::string> known;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const PairView& pair : state_.pairs) known.insert(pair.id);
    growing.MarkCompleted(known);
  }
  while (!stop_watch_) {
    for (const FolderEvent& event : growing.Poll(SteadySeconds())) {
      if (event.kind == FolderEvent::Kind::kPairComplete) {
        AddPair(event.pair);
      } else {
        std::lock_guard<std::mutex> lock(mutex_);
        SetStatus(event.stem + ": " + event.reason, true);
      }
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
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
  if (known >= dataset.pairs.size() ||
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
  const PairView& pair = state_.pairs[index];
  // The views move to the newest pair once it is loaded (not before: they would show nothing
  // meanwhile), unless the user looks at an older one.
  if (FollowsTo(index)) {
    state_.selected = index;
    state_.reprojection.reset();  // the last image stays up until this one's is decoded
    worker_.Enqueue([this] { EnsureSelectedImage(); });
    worker_.Enqueue([this, index] { ComputeReprojection(index); });
  }
  // The newest pair against the ghost board that was shown while it was taken.
  if (pair.camera && state_.next_pose && !watching_.empty()) {
    const SuggestionMatch match =
        MatchSuggestion(pair.camera->cam_from_board, *state_.next_pose, GuidanceOptions{});
    state_.ghost_match = "pair " + pair.id + " " + match.words;
    state_.ghost_matched = match.matches;
  }
}

void Controller::AddPair(const PairEntry& entry) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!state_.dataset) return;
  for (const PairView& pair : state_.pairs)
    if (pair.id == entry.id) return;
  state_.dataset->pairs.push_back(entry);
  PairView view;
  view.id = entry.id;
  state_.pairs.push_back(std::move(view));
  PairState saved;
  saved.id = entry.id;
  session_.pairs.push_back(std::move(saved));
  ++state_.loading_total;
  const int index = static_cast<int>(state_.pairs.size()) - 1;
  ++state_.generation;
  worker_.Enqueue([this, index] { LoadPair(index); });  // selects it when it follows (FollowsTo)
}

void Controller::AdviseFromState() {
  CalibrationOutcome outcome;
  PipelineOptions options;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!state_.solver.result || state_.next_pose) return;
    for (const PairView& pair : state_.pairs) outcome.pairs.push_back(FeaturesOf(pair));
    outcome.solution = ResultForCurrentPairs();
    options = PipelineOptionsFromState();
  }
  Advise(outcome, options);
}

void Controller::Advise(const CalibrationOutcome& outcome, const PipelineOptions& pipeline) {
  AdviseOptions options;
  Dataset dataset;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!state_.dataset) return;
    options.goal = state_.goal;
    dataset = *state_.dataset;
  }
  options.pipeline = pipeline;
  // The solve's pairs (a watched folder may have added some since).
  if (dataset.pairs.size() < outcome.pairs.size()) return;
  dataset.pairs.resize(outcome.pairs.size());
  const CaptureAdvice advice = AdviseCapture(dataset, outcome, options);
  std::lock_guard<std::mutex> lock(mutex_);
  state_.next_pose = advice.next;
  state_.next_pose_failure = advice.state && advice.state->done
                                 ? "the goal is met: no more poses needed"
                                 : advice.next_failure;
  bool rejected = false;
  for (size_t i = 0; i < advice.pairs.size() && i < state_.pairs.size(); ++i) {
    PairView& pair = state_.pairs[i];
    const PairAdvice& judged = advice.pairs[i];
    if (pair.id != judged.id) continue;
    pair.findings = judged.findings;
    // Following a capture, pre-flight's rejections apply, as `watch` applies them; on a dataset
    // they are shown on the rows and the user decides.
    if (!watching_.empty() && judged.status == PairStatus::kRejected &&
        pair.status == PairStatus::kAccepted) {
      pair.status = PairStatus::kRejected;
      pair.reason = judged.reason;
      rejected = true;
    }
  }
  ++state_.generation;
  if (!rejected) return;
  CommitEdit();
  RequestSolve();
}

}  // namespace calibench::ui
