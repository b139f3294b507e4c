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

FeedEnd FollowFeed(CaptureFeed& feed, const FeedLoopOptions& options, const FeedHandlers& handlers,
                   const FollowSink& sink) {
  const double first_look_start = SteadySeconds();
  double last_activity = first_look_start;
  bool opened = false;
  std::vector<PairEntry> read_before_open;  // the pairs read until the first look caught up
  for (;;) {
    if (handlers.stopped && handlers.stopped()) return FeedEnd::kStopped;
    // The board the user picked goes to the feed before it reads on: only this thread touches
    // the feed.
    if (handlers.take_picked_board)
      if (const auto picked = handlers.take_picked_board())
        if (!feed.SetBoard(picked->first, picked->second))
          Say(sink, "board", "", "this capture's board comes from its target.json");
    const double looked_s = SteadySeconds();
    const FeedUpdate update = feed.Poll(looked_s);
    // A recording that grows is alive even while no pair comes out of it (its board unknown).
    // The data came during the look, which may take long (a finished recording read whole, the
    // presets tried on its images): the silence starts when the look ends.
    if (update.data_arrived) last_activity = SteadySeconds();
    if (!update.events.empty()) last_activity = looked_s;
    if (handlers.looked) handlers.looked(feed, update);
    std::vector<PairEntry> pairs = CompletedPairs(update, sink);
    bool done = false;
    if (!opened) {
      // The capture opens once the first look has caught up with what is there and its camera
      // and board are known (a recording tells them with its first pair).
      read_before_open.insert(read_before_open.end(), pairs.begin(), pairs.end());
      const bool caught_up =
          (pairs.empty() && SteadySeconds() - first_look_start >= options.first_look_s) ||
          update.closed;
      if (caught_up && feed.Setup()) {
        Dataset read = *feed.Setup();
        read.manifest = feed.DatasetFolder();
        read.pairs = std::move(read_before_open);
        const bool any = !read.pairs.empty();
        opened = true;
        if (handlers.open) done = handlers.open(std::move(read), looked_s);
        // Idle means no new data: the time the handler took (a solve) is not the capture's
        // silence (a slow solve once ended a watch before the next poll could see the pair
        // already there).
        if (any) last_activity = SteadySeconds();
      }
    } else if (!pairs.empty()) {
      if (handlers.add) done = handlers.add(std::move(pairs), looked_s);
      last_activity = SteadySeconds();
    }
    if (done) return FeedEnd::kDone;
    if (update.closed) return FeedEnd::kClosed;
    if (options.idle_exit_s > 0 && SteadySeconds() - last_activity >= options.idle_exit_s)
      return FeedEnd::kIdle;
    std::this_thread::sleep_for(std::chrono::duration<double>(options.poll_s));
  }
}

}  // namespace calibench
