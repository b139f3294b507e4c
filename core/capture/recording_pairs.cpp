// The pair finder's second thread: each try judged (the board searched, the sweep decoded), the
// board chosen among the presets when none was given; and the finder's public face.
#include "core/capture/recording_pairs.h"

#include <exception>
#include <mutex>
#include <utility>

#include "core/capture/pair_verdict.h"
#include "core/capture/recording_pairs_impl.h"

namespace calibench {

void RecordingPairFinder::Impl::Work() {
  std::unique_lock lock(mutex);
  while (true) {
    wake_worker.wait(lock, [&] { return stopping || !queue.empty() || (finishing && !finished); });
    if (stopping) return;
    if (!queue.empty()) {
      Try attempt = std::move(queue.front());
      queue.pop_front();
      worker_idle.notify_all();
      if (worker_error) {  // the reader rethrows it; nothing more is tried
        ++tries_done;
        continue;
      }
      lock.unlock();
      Guard([&] { Process(std::move(attempt)); });
      lock.lock();
      ++tries_done;
      worker_idle.notify_all();
      continue;
    }
    // Finishing and nothing queued: the board is chosen from whatever tries came (or taken
    // as given at the last moment).
    if (!board && !worker_error) {
      lock.unlock();
      Guard([&] {
        if (!AdoptGivenBoard()) Decide(board_choice.Finish());
      });
      lock.lock();
    }
    DropWave();  // a motion that ended with the recording short of a wave
    finished = true;
    worker_idle.notify_all();
  }
}

template <typename F>
void RecordingPairFinder::Impl::Guard(F&& work) {
  try {
    work();
  } catch (...) {
    std::lock_guard lock(mutex);
    if (!worker_error) worker_error = std::current_exception();
    worker_idle.notify_all();
  }
}

void RecordingPairFinder::Impl::Process(Try attempt) {
  if (!board) AdoptGivenBoard();
  if (board) {
    ProcessWithBoard(attempt, std::nullopt);
    return;
  }
  HeldTry sample{std::move(attempt), std::nullopt};
  try {
    sample.image = DecodeTryMessageImage(sample.attempt.image, topics, options.limits);
  } catch (const std::invalid_argument&) {
  }
  Decide(board_choice.Offer(std::move(sample)));
  std::lock_guard lock(mutex);
  board_problem = board_choice.Problem();
}

bool RecordingPairFinder::Impl::AdoptGivenBoard() {
  std::optional<std::pair<BoardSpec, std::string>> given;
  {
    std::lock_guard lock(mutex);
    given = std::exchange(given_board, std::nullopt);
  }
  if (!given) return false;
  Decide(board_choice.Give(given->first, given->second));
  return true;
}

void RecordingPairFinder::Impl::Decide(BoardDecision decision) {
  for (const std::string& reason : decision.dropped) Drop(reason);
  if (!decision.board) return;
  {
    std::lock_guard lock(mutex);
    board = decision.board;
    stats.board_choice = decision.board_choice;
    board_problem.clear();
  }
  for (HeldTry& sample : decision.release)
    ProcessWithBoard(sample.attempt, std::move(sample.image));
}

void RecordingPairFinder::Impl::ProcessWithBoard(const Try& attempt,
                                                 std::optional<ImageU8> decoded) {
  if (HoldGaveAPair(attempt.hold)) {  // tries held while the board was chosen
    Drop(kHoldDone);
    return;
  }
  TryOutcome outcome =
      attempt.moving
          ? JudgeMovingTry(attempt, topics, *board, kept_poses, options, source, &frame_searches)
          : JudgeTry(attempt, std::move(decoded), topics, *board, kept_poses, options, source);
  std::lock_guard lock(mutex);
  stats.images_searched += outcome.searched;
  stats.boards_found += outcome.found;
  // The camera's word on the motion: a board it saw still ends a motion short of a wave.
  if (outcome.camera_still || (outcome.pair && !outcome.pair->Moving())) DropWave();
  if (outcome.camera_moving) moving_sweeps.insert(attempt.cloud.stamp_ns);
  if (!outcome.pair) {
    ++stats.dropped[outcome.dropped];
    return;
  }
  if (outcome.pair->Moving()) {
    KeepMoving(std::move(*outcome.pair));
    return;
  }
  kept_poses.push_back(outcome.pair->cam_from_board);
  if (attempt.hold > 0) satisfied_holds.insert(attempt.hold);
  if (!outcome.pair->stillness_checked) ++stats.kept_without_stillness_check;
  found.push_back(std::move(*outcome.pair));
}

void RecordingPairFinder::Impl::KeepMoving(FoundPair pair) {
  const std::int64_t stamp = pair.cloud_stamp_ns;
  if (!wave_start_ns) wave_start_ns = stamp;
  wave.push_back(std::move(pair));
  if (stamp - *wave_start_ns < Ns(options.moving_after_s)) return;  // not yet a wave
  // A moving pair's pose is one instant of a wave: it makes no later hold a duplicate.
  stats.moving_pairs += static_cast<int>(wave.size());
  for (FoundPair& moving : wave) found.push_back(std::move(moving));
  wave.clear();
}

void RecordingPairFinder::Impl::DropWave() {
  if (!wave.empty())
    stats.dropped["moving: the camera saw the board move for less than " +
                  MillisecondsText(options.moving_after_s) + " (a carry between holds)"] +=
        static_cast<int>(wave.size());
  wave.clear();
  wave_start_ns.reset();
}

RecordingPairFinder::RecordingPairFinder(std::string source, PairTopics topics,
                                         std::optional<BoardSpec> board,
                                         std::optional<CameraModel> camera,
                                         PairSelectionOptions options)
    : impl_(std::make_unique<Impl>(std::move(source), std::move(topics), std::move(board),
                                   std::move(camera), std::move(options))) {}

RecordingPairFinder::~RecordingPairFinder() = default;

void RecordingPairFinder::AddCloud(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
  impl_->AddCloud(data, log_time_ns);
}
void RecordingPairFinder::AddImage(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
  impl_->AddImage(data, log_time_ns);
}
void RecordingPairFinder::AddCameraInfo(std::span<const std::uint8_t> data) {
  impl_->AddCameraInfo(data);
}
void RecordingPairFinder::Finish() { impl_->Finish(); }

std::vector<FoundPair> RecordingPairFinder::TakePairs() {
  std::lock_guard lock(impl_->mutex);
  return std::exchange(impl_->found, {});
}

PairFinderStats RecordingPairFinder::Stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

std::optional<CameraModel> RecordingPairFinder::Camera() const { return impl_->camera; }

std::optional<BoardSpec> RecordingPairFinder::Board() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board;
}

std::string RecordingPairFinder::BoardProblem() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->board ? "" : impl_->board_problem;
}

void RecordingPairFinder::SetBoard(const BoardSpec& board, const std::string& source) {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->board) impl_->given_board = std::make_pair(board, source);
}

}  // namespace calibench
