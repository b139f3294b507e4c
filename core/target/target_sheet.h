// Printable targets at exact scale (`calibench target`): a board laid out on a paper sheet with a
// 100 mm ruler and a caption, written as PDF or SVG through cairo. The printer scaling the page
// ("fit to page") is the most common silent error in board calibration; the ruler lets the user
// see it before a single image is taken.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/base/types.h"
#include "core/board/board.h"

namespace calibench {

enum class Paper { kA4, kA3, kA2, kA1, kA0, kLetter };
std::string PaperName(Paper paper);  // "a4", ..., "letter"
std::optional<Paper> ParsePaperName(const std::string& name);
std::string PaperNames();  // "a4|a3|a2|a1|a0|letter", for messages
// Portrait [width, height] in millimetres (ISO 216; letter 8.5 x 11 in).
Vec2 PaperSizeMm(Paper paper);

enum class SheetOrientation { kAuto, kPortrait, kLandscape };
std::optional<SheetOrientation> ParseSheetOrientation(const std::string& name);

struct TargetSheetOptions {
  Paper paper = Paper::kA4;
  // auto: the one the pattern fits best, a ruler beside it preferred
  SheetOrientation orientation = SheetOrientation::kAuto;
  double margin_mm = 6.0;  // white border on every side: printers cannot ink the last ~4 mm
  // Room the ruler and its caption take beside the pattern, beyond the margin: below it (the
  // parameters above), else on its right (reading up the page; the parameters on the left). The
  // pattern stays centred on the sheet, as target.json's board_size says, and only a pattern
  // larger than the printable area (the paper less its margins) is refused.
  double band_mm = 11.0;

  bool Check(std::string* why) const;
};

// Where everything goes on the sheet; millimetres from the page's top-left corner, y down.
struct TargetSheet {
  BoardSpec board;  // board_size = the sheet, the pattern centred on it (target.json)
  Paper paper = Paper::kA4;
  bool landscape = false;
  Vec2 sheet_mm = Vec2::Zero();  // page [width, height]
  Vec2 pattern_top_left_mm = Vec2::Zero();
  // The ruler: below the pattern, reading left to right, its ticks below the baseline; or, where
  // only the side margin has room, right of it reading up the page, its ticks to the right. None
  // when neither has room (`note` says how to check the scale then).
  bool has_ruler = true;
  bool ruler_vertical = false;
  Vec2 ruler_start_mm = Vec2::Zero();  // the 0 mark, on the ruler's baseline
  double ruler_length_mm = 100.0;
  double ruler_tick_mm = 2.0;  // length of the millimetre ticks below the baseline
  // Each text by the middle of its baseline; vertical text reads up the page. Not drawn where no
  // strip beside the pattern holds it (the texts stay for the command to print).
  bool draw_title = true;
  bool draw_caption = true;
  Vec2 title_anchor_mm = Vec2::Zero();
  bool title_vertical = false;
  Vec2 caption_anchor_mm = Vec2::Zero();
  bool caption_vertical = false;
  std::string title;    // the pattern's parameters, above the pattern (or left of it)
  std::string caption;  // beside the ruler: the square size and how to print
  std::string note;     // for the user when something had no room (empty: everything fits)
};

// The largest square (mm) of `board`'s pattern that fits the printable area of the paper (less
// the margins) in the given orientation (auto: the better one).
double LargestSquareThatFitsMm(const BoardSpec& board, const TargetSheetOptions& options);

// Lays `board` out on the paper. Throws std::invalid_argument when the pattern is larger than the
// printable area, naming the largest square size that fits ("... the largest square that fits A4
// is 28.2 mm"), and for a board that fails BoardSpec::Check.
TargetSheet LayoutTargetSheet(const BoardSpec& board, const TargetSheetOptions& options);

// Draws the sheet into `path` (.pdf or .svg, chosen by the extension; the page is the paper's
// size) and returns nothing; throws IoError naming the file when it cannot be written and
// std::invalid_argument for another extension. Written atomically.
void WriteTargetSheet(const TargetSheet& sheet, const std::filesystem::path& path);

}  // namespace calibench
