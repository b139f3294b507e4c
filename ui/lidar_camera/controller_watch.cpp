// The controller's live side: solving by itself after every change, following a capture while it
// is written (`watch`'s loop one look at a time, FeedFollower, as background jobs on the worker:
// pairs join the list as they land), and after every solve `advise`'s pre-flight findings and
// next pose (the ghost board), with whether the newest pair matched the ghost.
#include <functional>
#include <utility>

#include "core/session/feed_loop.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

constexpr double kPollPeriod = 0.2;  // between looks [s]
// How long the first look at a feed lasts at least: longer than a folder's settle time (0.3 s by
// default) plus a poll, so that every pair there when following started has been reported before
// the dataset opens (and an earlier watch's session resumes over all of them).
constexpr double kFirstLookSeconds = 1.0;
const std::string kFollowLane = "follow";  // the worker's background lane for the looks

}  // namespace

// One followed capture: the opener until its feed opens, then `watch`'s loop one look at a time.
// Its steps hold it (shared) from job to job; the follower holds references into it.
struct Controller::FollowRun {
  std::optional<CaptureFeedOpener> opener;
  std::unique_ptr<CaptureFeed> feed;
  FeedLoopOptions loop;
  FeedHandlers handlers;
  FollowSink say;
  std::optional<FeedFollower> follower;
};

void Controller::SetAutoSolve(bool on) {
  std::lock_guard lock(mutex_);
  auto_solve_ = on;
  state_.auto_solve = on;
  ++state_.generation;
}

void Controller::RequestSolve() {
  mutex_.AssertHeld(__func__);
  if (!auto_solve_ || solve_queued_ || !state_.dataset) return;
  solve_queued_ = true;
  worker_.Enqueue([this] {
    {
      std::lock_guard lock(mutex_);
      solve_queued_ = false;
    }
    Solve(/*asked=*/false);
  });
}

void Controller::Follow(const CaptureFollowRequest& request) {
  StopWatching();
  stop_watch_ = false;
  // Pairs land while the user looks: the window's frames before the pairs' processing.
  worker_.LowerPriority();
  {
    std::lock_guard lock(mutex_);
    watching_ = std::filesystem::absolute(request.source);
    state_.watching = watching_;
  }
  auto run = std::make_shared<FollowRun>();
  // As `watch` opens it (core/session/capture_follow.h): a folder's camera and target waited for
  // (the status line says so), a recording's pairs written to the dataset folder.
  run->opener.emplace(request, [this](const FollowEvent& event) {
    std::lock_guard lock(mutex_);
    SetStatus((event.event == "waiting" ? "watching: " : "") + event.reason, false);
  });
  worker_.EnqueueBackground(kFollowLane, [this, run] { FollowStep(run); });
}

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

void Controller::FollowStep(const std::shared_ptr<FollowRun>& run) {
  if (stop_watch_) return;
  const auto look_again = [&] {
    worker_.EnqueueBackground(
        kFollowLane, [this, run] { FollowStep(run); }, kPollPeriod);
  };
  if (!run->follower) {
    std::string why;
    try {
      if (std::optional<OpenedFeed> opened = run->opener->Try(&why)) {
        run->feed = std::move(opened->feed);
        StartLooking(run.get());
      }
    } catch (const std::exception& e) {  // IoError naming the file, a folder not made
      why = e.what();
    }
    if (!run->follower && !why.empty()) {
      std::lock_guard lock(mutex_);
      if (!stop_watch_) SetStatus("cannot watch: " + why, true);
      return;
    }
    if (!run->follower)  // the folder's camera and target not there yet
      return look_again();
  }
  std::optional<FeedEnd> end;
  try {
    end = run->follower->Look();
  } catch (const IoError& e) {  // damaged data, a dataset folder that cannot be opened
    std::lock_guard lock(mutex_);
    SetStatus(std::string("cannot watch: ") + e.what(), true);
    return;
  }
  if (!end) return look_again();
  if (*end != FeedEnd::kClosed) return;
  std::lock_guard lock(mutex_);
  SetStatus("the recording was closed by its recorder; its " + std::to_string(state_.pairs.size()) +
                " pairs are in " + run->feed->DatasetFolder().string(),
            false);
}

void Controller::StartLooking(FollowRun* run) {
  // `watch`'s loop (core/session/feed_loop.h); the workbench's handlers add rows, which load and
  // solve on the worker, and say what happens on the status line.
  run->loop.poll_s = kPollPeriod;
  run->loop.first_look_s = kFirstLookSeconds;
  FeedHandlers& handlers = run->handlers;
  handlers.stopped = [this] { return stop_watch_.load(); };
  handlers.take_picked_board = [this] {
    std::lock_guard lock(mutex_);
    return std::exchange(picked_board_, std::nullopt);
  };
  handlers.looked = [this](const CaptureFeed& looked, const FeedUpdate&) {
    const std::string problem = looked.BoardProblem();
    std::lock_guard lock(mutex_);
    if (problem == state_.board_problem) return;
    state_.board_problem = problem;
    ++state_.generation;
  };
  // A session an earlier watch left is resumed over the pairs read again; the ones written since
  // join as new.
  handlers.open = [this](Dataset read, double) {
    std::vector<PairEntry> pairs = read.pairs;
    if (!ResumeGrownCapture(read)) OpenLoadedDataset(read, {}, ExistingSession::kResume);
    for (const PairEntry& pair : pairs) AddPair(pair);  // those a resumed session did not know
    return false;
  };
  handlers.add = [this](std::vector<PairEntry> pairs, double) {
    for (const PairEntry& pair : pairs) AddPair(pair);
    return false;
  };
  run->say = [this](const FollowEvent& event) {
    std::lock_guard lock(mutex_);
    if (event.event == "note" || event.event == "board")
      SetStatus(event.reason, event.event == "board");
    else
      SetStatus(event.name + ": " + event.reason, true);  // a pair's files incomplete or removed
  };
  run->follower.emplace(*run->feed, run->loop, run->handlers, run->say);
}

template <>
void Controller::Handle(const PickBoard& intent) {
  try {
    std::error_code error;
    const BoardSpec board = std::filesystem::is_regular_file(intent.board, error)
                                ? LoadTargetFile(intent.board)
                                : BoardPreset(intent.board);
    picked_board_ = std::make_pair(board, "picked in the workbench: " + intent.board);
    SetStatus("board " + intent.board + ": the held pairs are searched with it", false);
  } catch (const std::exception& e) {
    SetStatus(std::string("board not taken: ") + e.what(), true);
  }
}

void Controller::StopWatching() {
  stop_watch_ = true;
  // Waits for a look that runs (it may be adding pairs) and drops the next one.
  worker_.CancelBackground(kFollowLane);
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
  std::lock_guard lock(mutex_);
  if (!state_.dataset) return;
  for (const PairView& pair : state_.pairs)
    if (pair.id == entry.id) return;
  state_.dataset->pairs.push_back(entry);
  PairView view;
  view.id = entry.id;
  state_.pairs.push_back(std::move(view));
  if (job_) job_->record().AddPair(entry.id);
  ++state_.loading_total;
  const int index = static_cast<int>(state_.pairs.size()) - 1;
  ++state_.generation;
  worker_.Enqueue([this, index] { LoadPair(index); });  // selects it when it follows (FollowsTo)
}

void Controller::AdviseFromState() {
  std::optional<SolverResult> at;
  {
    std::lock_guard lock(mutex_);
    if (!job_ || !state_.solver.result || state_.next_pose) return;
    at = ResultForCurrentPairs();
  }
  Advise(at);
}

void Controller::Advise(const std::optional<SolverResult>& at) {
  if (!job_) return;
  {
    std::lock_guard lock(mutex_);
    job_->SetGoal(state_.goal);
    job_->SetHandTolerance(state_.hand_tolerance_m, state_.hand_tolerance_deg);
  }
  // The job's solve (pairs that joined since are judged after the next solve).
  const CaptureAdvice& advice = job_->Advise(at);
  std::lock_guard lock(mutex_);
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
  RecordWhatFollowed(/*same_step=*/true);
  RequestSolve();
}

}  // namespace calibench::ui
