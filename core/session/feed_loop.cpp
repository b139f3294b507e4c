#include "core/session/feed_loop.h"

#include <chrono>
#include <cmath>
#include <thread>

namespace calibench {

double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool FeedLoopOptions::Check(std::string* why) const {
  if (!(poll_s > 0 && std::isfinite(poll_s)))
    return *why = "the poll period must be > 0 (seconds)", false;
  if (!(first_look_s >= 0 && std::isfinite(first_look_s)))
    return *why = "the first look must last >= 0 seconds", false;
  if (!(idle_exit_s >= 0)) return *why = "--idle-exit must be >= 0 (seconds)", false;
  return true;
}

namespace {

// The pairs a look completed, in capture order; the other events told to the sink.
std::vector<PairEntry> CompletedPairs(const FeedUpdate& update, const FollowSink& sink) {
  std::vector<PairEntry> pairs;
  for (const std::string& note : update.notes) Say(sink, "note", "", note);
  for (const FolderEvent& event : update.events) {
    if (event.kind == FolderEvent::Kind::kPairComplete)
      pairs.push_back(event.pair);
    else
      Say(sink, event.kind == FolderEvent::Kind::kIncomplete ? "incomplete" : "removed", event.stem,
          event.reason);
  }
  return pairs;
}

}  // namespace

FeedFollower::FeedFollower(CaptureFeed& feed, const FeedLoopOptions& options,
                           const FeedHandlers& handlers, const FollowSink& sink)
    : feed_(feed),
      options_(options),
      handlers_(handlers),
      sink_(sink),
      first_look_start_(SteadySeconds()),
      last_activity_(first_look_start_) {}

std::optional<FeedEnd> FeedFollower::Look() {
  if (handlers_.stopped && handlers_.stopped()) return FeedEnd::kStopped;
  // The board the user picked goes to the feed before it reads on: only the look touches the
  // feed.
  if (handlers_.take_picked_board)
    if (const auto picked = handlers_.take_picked_board())
      if (!feed_.SetBoard(picked->first, picked->second))
        Say(sink_, "board", "", "this capture's board comes from its target.json");
  const double looked_s = SteadySeconds();
  const FeedUpdate update = feed_.Poll(looked_s);
  // A recording that grows is alive even while no pair comes out of it (its board unknown). The
  // data came during the look, which may take long (a finished recording read whole, the presets
  // tried on its images): the silence starts when the look ends.
  if (update.data_arrived) last_activity_ = SteadySeconds();
  if (!update.events.empty()) last_activity_ = looked_s;
  if (handlers_.looked) handlers_.looked(feed_, update);
  std::vector<PairEntry> pairs = CompletedPairs(update, sink_);
  bool done = false;
  if (!opened_) {
    // The capture opens once the first look has caught up with what is there and its camera and
    // board are known (a recording tells them with its first pair).
    read_before_open_.insert(read_before_open_.end(), pairs.begin(), pairs.end());
    const bool caught_up =
        (pairs.empty() && SteadySeconds() - first_look_start_ >= options_.first_look_s) ||
        update.closed;
    if (caught_up && feed_.Setup()) {
      Dataset read = *feed_.Setup();
      read.manifest = feed_.DatasetFolder();
      read.pairs = std::move(read_before_open_);
      read_before_open_.clear();
      const bool any = !read.pairs.empty();
      opened_ = true;
      if (handlers_.open) done = handlers_.open(std::move(read), looked_s);
      // Idle means no new data: the time the handler took (a solve) is not the capture's silence
      // (a slow solve once ended a watch before the next poll could see the pair already there).
      if (any) last_activity_ = SteadySeconds();
    }
  } else if (!pairs.empty()) {
    if (handlers_.add) done = handlers_.add(std::move(pairs), looked_s);
    last_activity_ = SteadySeconds();
  }
  if (done) return FeedEnd::kDone;
  if (update.closed) return FeedEnd::kClosed;
  if (options_.idle_exit_s > 0 && SteadySeconds() - last_activity_ >= options_.idle_exit_s)
    return FeedEnd::kIdle;
  return std::nullopt;
}

FeedEnd FollowFeed(CaptureFeed& feed, const FeedLoopOptions& options, const FeedHandlers& handlers,
                   const FollowSink& sink) {
  FeedFollower follower(feed, options, handlers, sink);
  for (;;) {
    if (const std::optional<FeedEnd> end = follower.Look()) return *end;
    std::this_thread::sleep_for(std::chrono::duration<double>(options.poll_s));
  }
}

}  // namespace calibench
