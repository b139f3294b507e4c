#include "core/capture/recording_board.h"

#include "core/base/types.h"

namespace calibench::recording_detail {
namespace {

// Tries held while the board is chosen (each holds a window's images: ~20 MB at 720p); with no
// preset in any of them they are given up, or, when a board no preset is shows, the oldest go.
constexpr std::size_t kMaxHeld = 12;
constexpr const char* kNoBoard = "board not found in the image";
constexpr const char* kUnknownBoard =
    "board not among the presets (give it: --board, a target file)";

}  // namespace

RecordingBoardChoice::RecordingBoardChoice(std::string source, int sample_images,
                                           bool stop_on_unknown)
    : source_(std::move(source)),
      sample_images_(sample_images),
      stop_on_unknown_(stop_on_unknown) {}

std::string RecordingBoardChoice::NoPresetExplains(const std::string& explanation) const {
  return source_ + ": no preset board explains the images (" + explanation +
         "): give the board with --board NAME|FILE or --target target.json, or put "
         "<recording>.target.json or target.json beside the recording";
}

BoardDecision RecordingBoardChoice::Offer(HeldTry sample) {
  if (sample.image) chooser_.Add(*sample.image);
  held_.push_back(std::move(sample));
  BoardDecision decision;
  if (!problem_.empty()) {  // known already: keep the newest, for a board given later
    if (held_.size() > kMaxHeld) {
      held_.pop_front();
      decision.dropped.push_back(kUnknownBoard);
    }
    return decision;
  }
  const int fits = chooser_.images_with_a_fit();
  if (fits >= sample_images_ || (held_.size() >= kMaxHeld && fits > 0)) return Choose();
  if (held_.size() < kMaxHeld) return decision;
  if (chooser_.images_with_a_board() >= sample_images_) {
    // A board is there, and no preset is it: the true reason, known now rather than at the end.
    problem_ = NoPresetExplains(chooser_.Choose().explanation);
    if (stop_on_unknown_) throw IoError(problem_);
    return decision;
  }
  // Nothing like a board yet (the user walking in): these tries cannot give a pair.
  decision.dropped.assign(held_.size(), kNoBoard);
  held_.clear();
  return decision;
}

BoardDecision RecordingBoardChoice::Give(const BoardSpec& board, const std::string& source) {
  BoardDecision decision;
  decision.board = board;
  decision.board_choice = "given while following: " + source;
  decision.release.assign(std::make_move_iterator(held_.begin()),
                          std::make_move_iterator(held_.end()));
  held_.clear();
  problem_.clear();
  return decision;
}

BoardDecision RecordingBoardChoice::Finish() {
  if (held_.empty()) return {};
  return Choose();
}

BoardDecision RecordingBoardChoice::Choose() {
  const BoardChoice choice = chooser_.Choose();
  if (!choice.board) throw IoError(NoPresetExplains(choice.explanation));
  BoardDecision decision;
  decision.board = choice.board;
  decision.board_choice = choice.explanation;
  decision.release.assign(std::make_move_iterator(held_.begin()),
                          std::make_move_iterator(held_.end()));
  held_.clear();
  return decision;
}

}  // namespace calibench::recording_detail
