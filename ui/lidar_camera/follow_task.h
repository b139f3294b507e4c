// A capture followed while it is written (a task of the controller,
// ui/lidar_camera/controller.h): `watch`'s loop (core/session/feed_loop.h, FeedFollower) one look
// at a time, every 0.2 s, as background jobs on the worker. The feed is waited for until it opens
// (why it cannot goes to the status line); then the controller opens its dataset and adds each
// pair as it lands (Controls), and a board the user picks for a recording no preset explains is
// handed to the next look. No GL, GLFW or ImGui.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "core/board/board.h"
#include "core/session/capture_follow.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class FollowTask {
 public:
  // What the controller does for a followed capture, on the worker with the mutex not held.
  struct Controls {
    // The feed's dataset, once its first look caught up: opened (an earlier watch's session
    // resumed over the pairs it knew).
    std::function<void(const Dataset&)> open;
    std::function<void(const PairEntry&)> add;  // one pair more, as it lands
  };
  FollowTask(TaskHost<Snapshot> host, Controls controls)
      : host_(host), controls_(std::move(controls)) {}

  // Follows `request`'s source as `watch` does (Snapshot::watching names it); the capture
  // followed before stops first. Mutex not held.
  void Start(const CaptureFollowRequest& request);
  // Stops following; returns once no look runs. Mutex not held (a look takes it).
  void Stop();
  // PickBoard: the board (a preset's name or a target file) the next look gives the feed, for the
  // pairs held for want of it. Mutex held.
  void Pick(const PickBoard& intent);

 private:
  struct Run;  // one followed capture: the opener until its feed opens, then the loop
  // One look (worker): for the feed until it opens, then the loop's; the next is enqueued 0.2 s
  // on unless following ended.
  void Step(const std::shared_ptr<Run>& run);
  // The feed opened: the loop's handlers, which open its dataset and add each pair (Controls).
  void StartLooking(Run* run);

  TaskHost<Snapshot> host_;
  Controls controls_;
  std::atomic<bool> stop_{false};
  std::optional<std::pair<BoardSpec, std::string>> picked_board_;  // Pick's and its words (mutex)
};

}  // namespace calibench::ui
