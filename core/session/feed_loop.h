// The one loop that follows a capture while it is written (docs/architecture.md, "The capture
// job"): look at the feed, say what the look found, open the capture once its camera and target
// are known and the first look has caught up, hand each later batch of completed pairs on, and end
// when stopped, closed, idle or done. `calibench watch` (core/session/capture_follow.h) and the
// workbench's live session (ui/lidar_camera/controller_watch.cpp) both run it; they differ only in
// what they do with the pairs (the job solves and saves; the workbench adds rows and solves on its
// worker).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/capture/capture_feed.h"
#include "core/session/follow_event.h"

namespace calibench {

struct FeedLoopOptions {
  double poll_s = 0.1;  // between looks [s]
  // The first look lasts at least this long [s]: the capture opens with every pair that was there
  // when following started, so that a session an earlier follower left resumes over all of them.
  double first_look_s = 0.0;
  double idle_exit_s = 0.0;  // end after this long without new data [s] (0 = never)
  bool Check(std::string* why) const;
};

// What a front end does with what the feed gives. Called from the look (the loop's thread, or the
// step that runs FeedFollower::Look); empty functions are skipped.
struct FeedHandlers {
  // Before each look: a board the user picked for the held pairs, and where it came from.
  std::function<std::optional<std::pair<BoardSpec, std::string>>()> take_picked_board;
  // After each look: the feed (its BoardProblem) and what the look brought.
  std::function<void(const CaptureFeed&, const FeedUpdate&)> looked;
  // Once: the capture's camera and target with the pairs the first look read, in capture order.
  // Returns true when the follower should end at once (its goal met already).
  std::function<bool(Dataset read, double seen_s)> open;
  // Each later batch of completed pairs, in capture order, and when they were seen [s, steady
  // clock]. Returns true when the follower should end (its goal met).
  std::function<bool(std::vector<PairEntry> pairs, double seen_s)> add;
  std::function<bool()> stopped;  // asked before each look
};

enum class FeedEnd { kStopped, kClosed, kIdle, kDone };

// The loop one look at a time, for a front end that runs each look as a step of its own (the
// workbench's worker, between its other jobs) rather than on a thread that sleeps: Look() once per
// poll period until it returns an end. Holds references to its arguments, which must outlive it.
class FeedFollower {
 public:
  FeedFollower(CaptureFeed& feed, const FeedLoopOptions& options, const FeedHandlers& handlers,
               const FollowSink& sink);
  // One look: asks `stopped`, hands a picked board to the feed, polls it, opens the capture or
  // adds the pairs. An end when following is over; nullopt: look again after options.poll_s.
  std::optional<FeedEnd> Look();

 private:
  CaptureFeed& feed_;
  const FeedLoopOptions& options_;
  const FeedHandlers& handlers_;
  const FollowSink& sink_;
  double first_look_start_ = 0, last_activity_ = 0;
  bool opened_ = false;
  std::vector<PairEntry> read_before_open_;  // the pairs read until the first look caught up
};

// Follows `feed` until one of FeedEnd (FeedFollower's looks, options.poll_s apart). Tells `sink`
// "note" (the feed's notes), "board" (a picked board the feed does not take) and "incomplete" /
// "removed" (a pair's files); the caller says the end in its own words. Throws what Poll throws
// (IoError naming the source) and what the handlers throw.
FeedEnd FollowFeed(CaptureFeed& feed, const FeedLoopOptions& options, const FeedHandlers& handlers,
                   const FollowSink& sink);

// Seconds on the steady clock: what FollowFeed's seen_s and a feed's Poll count in.
double SteadySeconds();

}  // namespace calibench
