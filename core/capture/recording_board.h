// Which board a recording shows when the user did not say, decided while its tries come (internal
// to core/io, for core/capture/recording_pairs.cpp): each try's image is offered to the presets
// (core/target/board_choice.h) and the try held; once a preset fits, the held tries are released
// to be searched with it. When the images show a board that no preset is (a preset found only
// inside a larger print), that is said as soon as it is known: `import` stops with it, `watch`
// keeps following with the newest tries held, until a board is given (Give).
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "core/capture/recording_try.h"
#include "core/target/board_choice.h"

namespace calibench::recording_detail {

// What an offer (or a given board, or the end) decided.
struct BoardDecision {
  std::optional<BoardSpec> board;    // known now: search `release` with it, and every later try
  std::string board_choice;          // how it was chosen
  std::vector<HeldTry> release;      // held tries to search now, in the order they came
  std::vector<std::string> dropped;  // one reason per try given up
};

class RecordingBoardChoice {
 public:
  // `source` names the recording in messages; a choice needs `sample_images` images that a
  // preset fits; `stop_on_unknown`: a board no preset explains throws (import) rather than
  // waiting for one to be given (watch).
  RecordingBoardChoice(std::string source, int sample_images, bool stop_on_unknown);

  BoardDecision Offer(HeldTry sample);
  // A board given while following (a target file that appeared, the user's pick).
  BoardDecision Give(const BoardSpec& board, const std::string& source);
  // The recording ended: the preset chosen from whatever came. Throws IoError when no preset
  // explains the images held.
  BoardDecision Finish();

  // Empty, or why no board is known while a board is visibly there (the words import stops with).
  const std::string& Problem() const { return problem_; }
  bool Holding() const { return !held_.empty(); }

 private:
  BoardDecision Choose();
  std::string NoPresetExplains(const std::string& explanation) const;

  std::string source_;
  int sample_images_ = 3;
  bool stop_on_unknown_ = true;
  BoardChooser chooser_;
  std::deque<HeldTry> held_;
  std::string problem_;
};

}  // namespace calibench::recording_detail
