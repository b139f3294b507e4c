#include "ui/lidar_camera/follow_task.h"

#include <filesystem>

#include "core/io/dataset.h"
#include "core/session/feed_loop.h"

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
struct FollowTask::Run {
  std::optional<CaptureFeedOpener> opener;
  std::unique_ptr<CaptureFeed> feed;
  FeedLoopOptions loop;
  FeedHandlers handlers;
  FollowSink say;
  std::optional<FeedFollower> follower;
};

void FollowTask::Start(const CaptureFollowRequest& request) {
  Stop();
  stop_ = false;
  // Pairs land while the user looks: the window's frames before the pairs' processing.
  host_.worker.LowerPriority();
  {
    std::lock_guard lock(host_.mutex);
    host_.state.watching = std::filesystem::absolute(request.source);
  }
  auto run = std::make_shared<Run>();
  // As `watch` opens it (core/session/capture_follow.h): a folder's camera and target waited for
  // (the status line says so), a recording's pairs written to the dataset folder.
  run->opener.emplace(request, [this](const FollowEvent& event) {
    std::lock_guard lock(host_.mutex);
    host_.SetStatus((event.event == "waiting" ? "watching: " : "") + event.reason, false);
  });
  host_.worker.EnqueueBackground(kFollowLane, [this, run] { Step(run); });
}

void FollowTask::Step(const std::shared_ptr<Run>& run) {
  if (stop_) return;
  const auto look_again = [&] {
    host_.worker.EnqueueBackground(
        kFollowLane, [this, run] { Step(run); }, kPollPeriod);
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
      std::lock_guard lock(host_.mutex);
      if (!stop_) host_.SetStatus("cannot watch: " + why, true);
      return;
    }
    if (!run->follower)  // the folder's camera and target not there yet
      return look_again();
  }
  std::optional<FeedEnd> end;
  try {
    end = run->follower->Look();
  } catch (const IoError& e) {  // damaged data, a dataset folder that cannot be opened
    std::lock_guard lock(host_.mutex);
    host_.SetStatus(std::string("cannot watch: ") + e.what(), true);
    return;
  }
  if (!end) return look_again();
  if (*end != FeedEnd::kClosed) return;
  std::lock_guard lock(host_.mutex);
  host_.SetStatus("the recording was closed by its recorder; its " +
                      std::to_string(host_.state.pairs.size()) + " pairs are in " +
                      run->feed->DatasetFolder().string(),
                  false);
}

void FollowTask::StartLooking(Run* run) {
  // `watch`'s loop (core/session/feed_loop.h); the workbench's handlers add rows, which load and
  // solve on the worker, and say what happens on the status line.
  run->loop.poll_s = kPollPeriod;
  run->loop.first_look_s = kFirstLookSeconds;
  FeedHandlers& handlers = run->handlers;
  handlers.stopped = [this] { return stop_.load(); };
  handlers.take_picked_board = [this] {
    std::lock_guard lock(host_.mutex);
    return std::exchange(picked_board_, std::nullopt);
  };
  handlers.looked = [this](const CaptureFeed& looked, const FeedUpdate&) {
    const std::string problem = looked.BoardProblem();
    std::lock_guard lock(host_.mutex);
    if (problem == host_.state.board_problem) return;
    host_.state.board_problem = problem;
    ++host_.state.generation;
  };
  // A session an earlier watch left is resumed over the pairs read again; the ones written since
  // join as new.
  handlers.open = [this](Dataset read, double) {
    controls_.open(read);
    // Those a resumed session did not know.
    for (const PairEntry& pair : read.pairs) controls_.add(pair);
    return false;
  };
  handlers.add = [this](std::vector<PairEntry> pairs, double) {
    for (const PairEntry& pair : pairs) controls_.add(pair);
    return false;
  };
  run->say = [this](const FollowEvent& event) {
    std::lock_guard lock(host_.mutex);
    if (event.event == "note" || event.event == "board")
      host_.SetStatus(event.reason, event.event == "board");
    else
      host_.SetStatus(event.name + ": " + event.reason,
                      true);  // a pair's files incomplete or removed
  };
  run->follower.emplace(*run->feed, run->loop, run->handlers, run->say);
}

void FollowTask::Pick(const PickBoard& intent) {
  host_.mutex.AssertHeld(__func__);
  try {
    std::error_code error;
    const BoardSpec board = std::filesystem::is_regular_file(intent.board, error)
                                ? LoadTargetFile(intent.board)
                                : BoardPreset(intent.board);
    picked_board_ = std::make_pair(board, "picked in the workbench: " + intent.board);
    host_.SetStatus("board " + intent.board + ": the held pairs are searched with it", false);
  } catch (const std::exception& e) {
    host_.SetStatus(std::string("board not taken: ") + e.what(), true);
  }
}

void FollowTask::Stop() {
  stop_ = true;
  // Waits for a look that runs (it may be adding pairs) and drops the next one.
  host_.worker.CancelBackground(kFollowLane);
}

}  // namespace calibench::ui
