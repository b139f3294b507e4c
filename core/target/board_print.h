// The printed board as geometry: where the ink is on the sheet. One renderer for everyone who
// draws a board — the simulator (camera images, LiDAR intensities), `calibench target` (the PDF or
// SVG the user prints) and the tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/types.h"
#include "core/board/board.h"

namespace calibench {

// An axis-aligned rectangle of ink in the board frame (metres; x right, y down on the print).
struct InkRect {
  Vec2 min = Vec2::Zero();
  Vec2 max = Vec2::Zero();
};

// The printed sheet in the board frame (BoardSpec): black ink on white paper, the pattern centred
// on the sheet. Checkerboards: square (0, 0), top left, is black (as on OpenCV's ChArUco drawing).
// ChArUco: exactly OpenCV 4.6's CharucoBoard::create() layout for the same parameters — its
// markers (ids, corners, bits with a one-cell black border) in the white squares, the other
// squares black; edges are exact, not sampled from a raster.
// Throws std::invalid_argument for an unknown ChArUco dictionary.
class BoardPrint {
 public:
  explicit BoardPrint(const BoardSpec& board);
  const BoardSpec& board() const { return board_; }
  // Whether a board-frame point (metres, z = 0) lies on the sheet.
  bool InSheet(const Vec2& xy) const {
    return std::abs(xy.x()) <= half_sheet_.x() && std::abs(xy.y()) <= half_sheet_.y();
  }
  // Reflectance at a point of the sheet (board frame, metres): 0 = ink, 1 = paper (also on the
  // white margin).
  double Reflectance(const Vec2& xy) const;
  // Every area of ink, rows of marker cells merged into runs: what a printer lays down.
  std::vector<InkRect> Ink() const;

 private:
  // One ArUco marker in a white square: its extent and its cells (row-major from the marker's
  // top-left corner, border included; 1 = ink).
  struct Marker {
    Vec2 min = Vec2::Zero();
    Vec2 max = Vec2::Zero();
    int cells = 0;  // per side, border included
    std::vector<std::uint8_t> ink;
  };
  bool SquareIsBlack(int i, int j) const;

  BoardSpec board_;
  Vec2 half_sheet_;                    // metres
  Vec2 half_pattern_;                  // metres
  std::vector<int> marker_of_square_;  // ChArUco: per square (row-major), marker index or -1
  std::vector<Marker> markers_;
};

}  // namespace calibench
