#include "core/target/board_choice.h"

#include <algorithm>
#include <cstdio>

#include "core/target/board_camera.h"

namespace calibench {

std::vector<std::string> ChoosablePresets() { return {"a3", "a4", "charuco-a3", "charuco-a4"}; }

namespace {

std::string Describe(const std::string& name, const BoardSpec& board) {
  char text[160];
  std::snprintf(text, sizeof(text), "%s (%s %dx%d, %.0f mm squares)", name.c_str(),
                board.type == BoardType::kCheckerboard ? "checkerboard" : "ChArUco", board.cols,
                board.rows, board.square_size * 1000);
  return text;
}

}  // namespace

BoardChooser::BoardChooser() {
  for (const std::string& name : ChoosablePresets()) tallies_.push_back({name, BoardPreset(name)});
}

void BoardChooser::Add(const ImageU8& image) {
  ++images_;
  bool fit_any = false, board_any = false;
  for (Tally& tally : tallies_) {
    const BoardFit fit = FitBoard(image, tally.board);
    tally.fits += fit == BoardFit::kFits;
    tally.part_of_larger += fit == BoardFit::kPartOfLarger;
    fit_any = fit_any || fit == BoardFit::kFits;
    board_any = board_any || fit == BoardFit::kFits || fit == BoardFit::kPartOfLarger;
  }
  images_with_a_fit_ += fit_any;
  images_with_a_board_ += board_any;
}

BoardChoice BoardChooser::Choose() const {
  std::vector<Tally> tallies = tallies_;
  std::stable_sort(tallies.begin(), tallies.end(),
                   [](const Tally& a, const Tally& b) { return a.fits > b.fits; });
  BoardChoice choice;
  const std::string of = " of " + std::to_string(images_) + " images";
  std::string others;
  for (std::size_t i = 0; i < tallies.size(); ++i) {
    const Tally& tally = tallies[i];
    if (i == 0 && tally.fits > 0) continue;
    std::string text = tally.name + ": ";
    if (tally.fits > 0) text += "fits " + std::to_string(tally.fits) + of;
    if (tally.part_of_larger > 0)
      text += std::string(tally.fits > 0 ? ", " : "") + "part of a larger board in " +
              std::to_string(tally.part_of_larger) + of;
    if (tally.fits == 0 && tally.part_of_larger == 0) text += "not found";
    others += (others.empty() ? "" : "; ") + text;
  }
  const Tally& best = tallies.front();
  const bool tie = tallies.size() > 1 && tallies[1].fits == best.fits;
  if (best.fits == 0 || tie) {
    choice.explanation =
        (tie && best.fits > 0 ? "two presets fit equally: " : "") + others +
        (tie && best.fits > 0 ? "; " + best.name + ": fits " + std::to_string(best.fits) + of : "");
    return choice;
  }
  choice.board = best.board;
  choice.name = best.name;
  choice.explanation =
      Describe(best.name, best.board) + ": fits " + std::to_string(best.fits) + of + "; " + others;
  return choice;
}

}  // namespace calibench
