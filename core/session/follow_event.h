// What following a capture says (core/session/feed_loop.h, core/session/capture_follow.h): one
// event per thing that happened, told to a sink that prints it (`watch`: words or JSON lines) or
// shows it (the workbench's status line).
#pragma once

#include <functional>
#include <string>

#include "core/results/pair_status.h"

namespace calibench {

struct CaptureAdvice;  // core/guidance/advise.h

// One thing the follower says. `event` names it: "waiting" (for the folder's camera and
// target), "note", "board" (a picked board the capture does not take: its target.json says),
// "incomplete" / "removed" (a pair's files), "resumed" (pairs from an earlier
// watch's feature cache), "error" (a cache or session not written), "pair" (a verdict, new or
// changed: `accepted`, `reason`), "solve" (`advice`, `latency_s` from seeing the pairs to the
// advice), "end" (why the watch ended).
struct FollowEvent {
  std::string event;
  std::string name;       // the pair or file it is about ("" when none)
  std::string reason;     // in words
  bool accepted = false;  // "pair": its verdict and status
  PairStatus status = PairStatus::kPending;
  const CaptureAdvice* advice = nullptr;  // "solve" only; valid during the call
  double latency_s = 0.0;
};
using FollowSink = std::function<void(const FollowEvent&)>;

// Tells `sink` an event that carries only words.
inline void Say(const FollowSink& sink, const std::string& event, const std::string& name,
                const std::string& reason) {
  FollowEvent e;
  e.event = event;
  e.name = name;
  e.reason = reason;
  sink(e);
}

}  // namespace calibench
