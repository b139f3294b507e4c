// Which printed board a recording shows, when the user did not say: the printable presets tried
// on a few images of the board held still, the one that fits (not merely found inside a larger
// print) chosen, or a refusal that says what to pass instead.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/board/board.h"

namespace calibench {

struct BoardChoice {
  std::optional<BoardSpec> board;  // nullopt = no preset explains the images
  std::string name;                // the preset's name when chosen
  // One line: "a3 (7x5 corners, 40 mm squares): fits 3 of 3 images; a4: part of a larger
  // board in 3" or, without a choice, why each preset was ruled out.
  std::string explanation;
};

// The presets tried: the printable ones (a3, a4, charuco-a3, charuco-a4). "paper" (1.6 m, the
// paper's simulated board) shares a3's grid and cannot be told from it by the image alone.
std::vector<std::string> ChoosablePresets();

// Tries every choosable preset on each image given; Choose() names the preset that fits the most
// images (at least one; a tie between presets is no choice).
class BoardChooser {
 public:
  BoardChooser();
  void Add(const ImageU8& image);
  int images() const { return images_; }
  int images_with_a_fit() const { return images_with_a_fit_; }
  // Images where some preset was found, fitting or as part of a larger print: a board is there.
  int images_with_a_board() const { return images_with_a_board_; }
  BoardChoice Choose() const;

 private:
  struct Tally {
    std::string name;
    BoardSpec board;
    int fits = 0, part_of_larger = 0;
  };
  std::vector<Tally> tallies_;
  int images_ = 0;
  int images_with_a_fit_ = 0;
  int images_with_a_board_ = 0;
};

}  // namespace calibench
