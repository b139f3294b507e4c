// Internal to core/capture/recording_pairs.cpp: the pair finder's state and its reader side (the
// recording's thread, inline here); its second thread's steps are defined in the .cpp. Included
// by nothing else (the names below are brought into calibench for those two files).
#pragma once

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "core/capture/pair_verdict.h"
#include "core/capture/recording_board.h"
#include "core/capture/recording_pairs.h"
#include "core/recording/ros_messages.h"

namespace calibench {

using recording_detail::BoardDecision;
using recording_detail::Copy;
using recording_detail::HeldTry;
using recording_detail::Ns;
using recording_detail::StampedBytes;
using recording_detail::StampOr;
using recording_detail::Try;

namespace recording_pairs_detail {

// Sweeps and images stay this long beyond the stillness window and the pairing offset behind
// the newest stamp: a sweep is judged kJudgeLagS after its window has passed, and its try needs
// the images back to the window's start.
inline constexpr double kKeepBeyondWindowS = 0.5;
// A sweep is judged once stamps this far past its window have arrived: the recorder may store
// an image a little after a later sweep.
inline constexpr double kJudgeLagS = 0.25;
// Tries waiting for the camera intrinsics (CameraInfo late in the recording); older ones drop.
inline constexpr std::size_t kMaxWaitingForCamera = 8;
// Tries queued for the second thread (each holds its window's images: ~20 MB at 720p); the
// reader waits beyond that, so memory stays bounded whatever the recording's length.
inline constexpr std::size_t kMaxQueuedTries = 2;
inline constexpr const char* kHoldDone = "not needed: its hold already gave a pair";

}  // namespace recording_pairs_detail

using recording_pairs_detail::kHoldDone;
using recording_pairs_detail::kJudgeLagS;
using recording_pairs_detail::kKeepBeyondWindowS;
using recording_pairs_detail::kMaxQueuedTries;
using recording_pairs_detail::kMaxWaitingForCamera;

struct RecordingPairFinder::Impl {
  Impl(std::string source_in, PairTopics topics_in, std::optional<BoardSpec> board_in,
       std::optional<CameraModel> camera_in, PairSelectionOptions options_in)
      : source(std::move(source_in)),
        topics(std::move(topics_in)),
        board(std::move(board_in)),
        camera(std::move(camera_in)),
        options(std::move(options_in)) {
    std::string why;
    if (!options.Check(&why)) throw IoError(source + ": pair selection options: " + why);
    keep_ns =
        Ns(std::max({options.still_window_s, options.ringless_integration_s, MovingReachS()}) +
           options.max_pair_offset_s + kKeepBeyondWindowS);
    worker = std::thread([this] { Work(); });
  }

  ~Impl() {
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    wake_worker.notify_all();
    if (worker.joinable()) worker.join();
  }

  // ---- reader side ---------------------------------------------------------------------------

  struct RecentCloud {
    StampedBytes cloud;
    int hold = 0;
    bool judged = false;
    // A moving sweep early in its motion: tried once the motion has lasted moving_after_s (a
    // wave, from its start), dropped when a still sweep ends it first (a carry between holds).
    bool deferred = false;
  };
  struct Hold {
    int tries = 0;
    std::int64_t last_try_ns = 0;
    std::uint64_t last_try_serial = 0;  // 0: none queued yet
    bool gave_a_pair = false;
  };

  void Drop(const std::string& reason) {
    std::lock_guard lock(mutex);
    ++stats.dropped[reason];
  }
  void Count(std::int64_t PairFinderStats::*messages) {
    std::lock_guard lock(mutex);
    ++(stats.*messages);
  }

  void RethrowWorkerError() {
    std::lock_guard lock(mutex);
    if (worker_error) std::rethrow_exception(worker_error);
  }

  void AddCloud(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
    RethrowWorkerError();
    Count(&PairFinderStats::clouds);
    CloudMessage message;
    try {
      message = DecodeCloudMessage(data, topics.livox_cloud, topics.cloud, options.limits);
    } catch (const std::invalid_argument&) {
      Drop("cloud message unreadable");
      return;
    }
    if (!message.cloud.HasRing() && !ringless && options.ringless_integration_s > 0) {
      // Decided on the first sweep that lacks rings (a recording's LiDAR does not change).
      ringless = true;
      window_s = std::max(options.still_window_s, options.ringless_integration_s);
    }
    const std::int64_t stamp = StampOr(message.header, log_time_ns);
    SweepGrid grid = MakeSweepGrid(message.cloud, options.lidar_motion);
    if (previous_grid) noise_floor.Add(CompareSweeps(*previous_grid, grid, options.lidar_motion));
    if (!hold_reference ||
        !CompareSweeps(*hold_reference, grid, options.lidar_motion, noise_floor.Fraction()).agree) {
      ++current_hold;
      hold_reference = grid;
    }
    previous_grid = std::move(grid);
    recent_clouds.push_back({{stamp, Copy(data)}, current_hold, false});
    Advance(stamp);
  }

  void AddImage(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
    RethrowWorkerError();
    Count(&PairFinderStats::images);
    std::int64_t stamp = log_time_ns;
    try {
      stamp = StampOr(DecodeRosHeader(data, topics.image), log_time_ns);
    } catch (const std::invalid_argument&) {
      // Kept by its log time: the try that picks it reports it unreadable.
    }
    const auto at = std::upper_bound(
        recent_images.begin(), recent_images.end(), stamp,
        [](std::int64_t t, const StampedBytes& image) { return t < image.stamp_ns; });
    recent_images.insert(at, {stamp, Copy(data)});
    Advance(stamp);
  }

  void AddCameraInfo(std::span<const std::uint8_t> data) {
    RethrowWorkerError();
    if (camera) return;
    try {
      camera = DecodeCameraInfo(data, topics.camera_info).camera;
    } catch (const std::invalid_argument& error) {
      camera_problem = error.what();
      return;
    }
    for (Try& waiting : waiting_for_camera) {
      waiting.camera = *camera;
      Queue(std::move(waiting));
    }
    waiting_for_camera.clear();
  }

  void Advance(std::int64_t stamp) {
    horizon_ns = std::max(horizon_ns, stamp);
    // A moving sweep's try takes the frames up to moving_images_s after it.
    const std::int64_t ready = horizon_ns - Ns(std::max(window_s / 2, MovingHalfWindowS()) +
                                               options.max_pair_offset_s + kJudgeLagS);
    for (RecentCloud& cloud : recent_clouds)
      if (!cloud.judged && cloud.cloud.stamp_ns <= ready) Judge(&cloud);
    const std::int64_t oldest = horizon_ns - keep_ns;
    while (!recent_clouds.empty() && recent_clouds.front().judged &&
           !recent_clouds.front().deferred && recent_clouds.front().cloud.stamp_ns < oldest)
      recent_clouds.pop_front();
    while (!recent_images.empty() && recent_images.front().stamp_ns < oldest)
      recent_images.pop_front();
  }

  // Whether the LiDAR saw the scene still around `cloud`: kStill when every other sweep within
  // the window is of its hold, kMoving when one is not, kUnknown with no other sweep there.
  enum class LidarView { kStill, kMoving, kUnknown };
  LidarView SeenByLidar(const RecentCloud& cloud) const {
    const std::int64_t half = Ns(options.still_window_s / 2);
    LidarView view = LidarView::kUnknown;
    for (const RecentCloud& other : recent_clouds) {
      if (&other == &cloud || std::abs(other.cloud.stamp_ns - cloud.cloud.stamp_ns) > half)
        continue;
      if (other.hold != cloud.hold) return LidarView::kMoving;
      view = LidarView::kStill;
    }
    return view;
  }

  // The half-width of a moving sweep's frames; 0 when moving sweeps are never tried.
  double MovingHalfWindowS() const {
    return options.moving_after_s > 0 ? options.moving_images_s : 0.0;
  }
  // How far back a moving sweep's try may reach when made: its motion's start, and its frames.
  // (Sweeps are judged a moving_images_s after their stamp: the frames after them are in.)
  double MovingReachS() const {
    return options.moving_after_s > 0 ? options.moving_after_s + 2 * options.moving_images_s : 0.0;
  }

  // The motion's sweeps held back (RecentCloud::deferred): tried as moving, or dropped.
  void SettleDeferred(bool try_them) {
    for (RecentCloud& other : recent_clouds) {
      if (!other.deferred) continue;
      other.deferred = false;
      if (try_them)
        MakeTry(other, --lone_hold, /*moving=*/true);
      else
        Drop("not tried: the LiDAR saw the scene move");
    }
  }

  // A sweep the LiDAR saw still: its hold's tries, the first at once, then one every retry_s
  // until one gives a pair. It ends a motion (the sweeps held back dropped as a carry's) — but
  // amid a motion only once its hold's try has not shown the board move: a dense LiDAR's learnt
  // noise floor can be a steady wave's own change (a recording that is all wave has no still sweep
  // to learn it from: an OS0-128 took 7 of a wave's 80 sweeps for holds, and the 16 held back
  // before them were dropped as a carry's), so there the camera's word decides, its try waited
  // for at once. The tries are those of any hold, so a still-hold recording's pairs stay as they
  // were.
  void JudgeStill(const RecentCloud& cloud) {
    const std::int64_t stamp = cloud.cloud.stamp_ns;
    const bool ask_camera = in_motion && !ringless && options.moving_after_s > 0;
    auto end_motion = [&] {
      in_motion = false;
      last_still_ns = stamp;
      still_since_ns = stamp;
      SettleDeferred(false);  // the motion stopped short of a wave
    };
    if (!ask_camera) end_motion();
    Hold& hold = holds[cloud.hold];
    // The hold's last try decides whether more are needed: waiting for it (once per try, a
    // search's time) keeps the tries, and so the pairs and every count, the same for any
    // timing of the two threads.
    if (hold.last_try_serial > 0 && !hold.gave_a_pair) {
      WaitForTry(hold.last_try_serial);
      hold.gave_a_pair = HoldGaveAPair(cloud.hold);
    }
    if (hold.gave_a_pair) {
      if (ask_camera) end_motion();
      Drop(kHoldDone);
      return;
    }
    if (hold.tries > 0 && stamp - hold.last_try_ns < Ns(options.retry_s)) {
      Drop("not tried: its hold was tried within " + MillisecondsText(options.retry_s));
      return;
    }
    ++hold.tries;
    hold.last_try_ns = stamp;
    hold.last_try_serial = MakeTry(cloud, cloud.hold);
    if (!ask_camera) return;
    const bool camera_moving = TryShowedMotion(hold.last_try_serial, stamp);
    hold.gave_a_pair = HoldGaveAPair(cloud.hold);
    if (!camera_moving) end_motion();
  }

  // Whether the still try `serial` of the sweep stamped `stamp` showed the board move, once the
  // worker has judged it (0: a try not queued, which showed nothing).
  bool TryShowedMotion(std::uint64_t serial, std::int64_t stamp) {
    if (serial == 0) return false;
    WaitForTry(serial);
    std::lock_guard lock(mutex);
    return moving_sweeps.count(stamp) > 0;
  }

  // A ring-less (Livox-class) LiDAR sees nothing still, even at a hold: a sweep is tried blind
  // every retry_s (the sweeps around it integrated) and the camera says whether the board was
  // held. Its word on a blind try is also a wave's: the sweeps between blind tries are held back
  // (RecentCloud::deferred), and once blind tries have shown the board move for moving_after_s
  // since the last that did not, they and every later sweep are tried as moving (each frame
  // alone); a blind try whose images do not show it move ends the motion, the sweeps held back
  // dropped as they always were. The blind try's sweep is its say, in a wave too.
  void JudgeRingless(RecentCloud* cloud) {
    const std::int64_t stamp = cloud->cloud.stamp_ns;
    if (stamp - last_still_ns >= Ns(options.lidar_blind_s) &&
        stamp - last_blind_try_ns >= Ns(options.retry_s)) {
      last_blind_try_ns = stamp;
      in_motion = TryShowedMotion(MakeTry(*cloud, --lone_hold), stamp);
      if (!in_motion) {
        still_since_ns = stamp;
        SettleDeferred(false);
      } else if (stamp - still_since_ns >= Ns(options.moving_after_s)) {
        SettleDeferred(true);
      }
      return;
    }
    if (in_motion && stamp - still_since_ns >= Ns(options.moving_after_s)) {
      SettleDeferred(true);
      MakeTry(*cloud, --lone_hold, /*moving=*/true);
      return;
    }
    cloud->deferred = true;
  }

  void Judge(RecentCloud* cloud) {
    cloud->judged = true;
    const std::int64_t stamp = cloud->cloud.stamp_ns;
    if (still_since_ns == INT64_MIN) still_since_ns = stamp;  // the recording's first sweep
    const LidarView view = SeenByLidar(*cloud);
    if (view == LidarView::kStill) {
      JudgeStill(*cloud);
    } else if (view == LidarView::kUnknown) {
      MakeTry(*cloud, --lone_hold);  // a sweep alone in its window: the camera judges
    } else if (!ringless && options.moving_after_s > 0) {
      // A board that never stops: each sweep a moving pair, from the motion's start (a ring-less
      // LiDAR's wave is the camera's to tell: JudgeRingless). A board held still where something
      // else moves is told apart by the camera (JudgeMovingTry).
      in_motion = true;
      if (stamp - still_since_ns < Ns(options.moving_after_s)) {
        cloud->deferred = true;
        return;
      }
      SettleDeferred(true);
      MakeTry(*cloud, --lone_hold, /*moving=*/true);
    } else if (ringless && options.moving_after_s > 0) {
      JudgeRingless(cloud);
    } else if (stamp - last_still_ns >= Ns(options.lidar_blind_s) &&
               stamp - last_blind_try_ns >= Ns(options.retry_s)) {
      last_blind_try_ns = stamp;
      MakeTry(*cloud, --lone_hold);
    } else {
      Drop("not tried: the LiDAR saw the scene move");
    }
  }

  void WaitForTry(std::uint64_t serial) {
    std::unique_lock lock(mutex);
    worker_idle.wait(lock, [&] { return tries_done >= serial || worker_error; });
    if (worker_error) std::rethrow_exception(worker_error);
  }

  bool HoldGaveAPair(int hold) {
    std::lock_guard lock(mutex);
    return satisfied_holds.count(hold) > 0;
  }

  // The try's serial once queued for the second thread; 0 when it was not (no image, or waiting
  // for the camera intrinsics).
  std::uint64_t MakeTry(const RecentCloud& cloud, int hold, bool moving = false) {
    {
      std::lock_guard lock(mutex);
      ++stats.tries;
    }
    const std::int64_t stamp = cloud.cloud.stamp_ns;
    const StampedBytes* nearest = nullptr;
    for (const StampedBytes& image : recent_images)
      if (!nearest || std::abs(image.stamp_ns - stamp) < std::abs(nearest->stamp_ns - stamp))
        nearest = &image;
    const double pairing_s = moving ? options.moving_images_s : options.max_pair_offset_s;
    if (!nearest || std::abs(nearest->stamp_ns - stamp) > Ns(pairing_s)) {
      Drop("no image within " + MillisecondsText(pairing_s));
      return 0;
    }
    Try attempt;
    attempt.hold = hold;
    attempt.moving = moving;
    attempt.cloud = cloud.cloud;
    attempt.image = *nearest;
    const std::int64_t half = Ns(moving ? options.moving_images_s : window_s / 2);
    for (const StampedBytes& image : recent_images)
      if (&image != nearest && std::abs(image.stamp_ns - stamp) <= half)
        attempt.others.push_back(image);
    // A ring-less LiDAR's sweeps of the span, for the pair's cloud: the camera checks that the
    // board held still over the same span.
    attempt.ringless = ringless;
    if (ringless && !moving)
      for (const RecentCloud& other : recent_clouds)
        if (&other != &cloud && std::abs(other.cloud.stamp_ns - stamp) <= half)
          attempt.integrated.push_back(other.cloud);
    if (!camera) {
      if (waiting_for_camera.size() == kMaxWaitingForCamera) {
        waiting_for_camera.pop_front();
        Drop("no camera intrinsics yet");
      }
      waiting_for_camera.push_back(std::move(attempt));
      return 0;
    }
    attempt.camera = *camera;
    return Queue(std::move(attempt));
  }

  std::uint64_t Queue(Try attempt) {
    std::unique_lock lock(mutex);
    worker_idle.wait(lock, [&] { return queue.size() < kMaxQueuedTries || worker_error; });
    if (worker_error) std::rethrow_exception(worker_error);
    queue.push_back(std::move(attempt));
    wake_worker.notify_all();
    return ++tries_queued;
  }

  void Finish() {
    RethrowWorkerError();
    for (RecentCloud& cloud : recent_clouds)
      if (!cloud.judged) Judge(&cloud);
    SettleDeferred(false);  // a motion shorter than a wave at the recording's end
    if (!camera && !waiting_for_camera.empty())
      throw IoError(source + ": no usable camera intrinsics on " + topics.camera_info_topic +
                    (camera_problem.empty() ? "" : " (" + camera_problem + ")") +
                    ": give them with --camera FILE");
    std::unique_lock lock(mutex);
    finishing = true;
    wake_worker.notify_all();
    worker_idle.wait(lock, [&] { return finished || worker_error; });
    if (worker_error) std::rethrow_exception(worker_error);
  }

  // ---- second thread (recording_pairs_worker.cpp) -------------------------------------------

  void Work();
  // Runs `work`, any exception kept for the reader to rethrow.
  template <typename F>
  void Guard(F&& work);
  void Process(Try attempt);
  // A board given while following (SetBoard), taken at the next try; true when taken.
  bool AdoptGivenBoard();
  // What the board choice decided: the board once known, the held tries searched with it.
  void Decide(BoardDecision decision);
  void ProcessWithBoard(const Try& attempt, std::optional<ImageU8> decoded);
  // A moving pair, held until the camera has seen the board move for moving_after_s (then it
  // and the motion's earlier ones are found), or dropped when the camera sees it still first
  // (DropWave: a carry between holds, a LiDAR that sees nothing still). With mutex held.
  void KeepMoving(FoundPair pair);
  void DropWave();

  // ---- state ---------------------------------------------------------------------------------

  const std::string source;
  const PairTopics topics;
  std::optional<BoardSpec> board;     // set by the worker (under `mutex`) once chosen
  std::optional<CameraModel> camera;  // the reader's
  std::string camera_problem;
  const PairSelectionOptions options;
  std::int64_t keep_ns = 0;
  bool ringless = false;                     // the sweeps carry no rings: holds are integrated
  double window_s = options.still_window_s;  // the stillness (and integration) window [s]

  // Reader.
  std::deque<RecentCloud> recent_clouds;
  std::deque<StampedBytes> recent_images;  // by stamp
  std::optional<SweepGrid> hold_reference, previous_grid;
  SweepNoiseFloor noise_floor{options.lidar_motion};
  int current_hold = 0;
  int lone_hold = 0;  // negative ids: tries that belong to no hold
  std::map<int, Hold> holds;
  std::int64_t horizon_ns = INT64_MIN;
  std::int64_t last_still_ns = 0;
  std::int64_t still_since_ns = INT64_MIN;  // the last still sweep's stamp, else the first's
  bool in_motion = false;  // the last sweep judged was a motion's (deferred or tried as moving)
  std::int64_t last_blind_try_ns = INT64_MIN / 2;
  std::deque<Try> waiting_for_camera;

  // Worker.
  recording_detail::RecordingBoardChoice board_choice{source, options.board_sample_images,
                                                      options.stop_on_unknown_board};
  std::vector<Pose> kept_poses;
  FrameSearches frame_searches;
  std::vector<FoundPair> wave;                // moving pairs not yet known to be a wave's
  std::optional<std::int64_t> wave_start_ns;  // the first of them

  // Shared, under `mutex`.
  mutable std::mutex mutex;
  std::condition_variable wake_worker, worker_idle;
  std::deque<Try> queue;
  bool finishing = false, finished = false, stopping = false;
  std::exception_ptr worker_error;
  std::vector<FoundPair> found;
  std::set<int> satisfied_holds;         // holds that gave a pair
  std::set<std::int64_t> moving_sweeps;  // sweeps whose still try's images showed the board move
  std::uint64_t tries_queued = 0, tries_done = 0;
  PairFinderStats stats;
  std::string board_problem;  // the board choice's Problem(), for the reader
  std::optional<std::pair<BoardSpec, std::string>> given_board;  // SetBoard's, until taken
  std::thread worker;  // last: started once everything above exists
};

}  // namespace calibench
