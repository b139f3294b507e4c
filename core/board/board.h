// Printed calibration targets: the board specification, its corner points and named presets.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/base/types.h"

namespace calibench {

enum class BoardType { kCheckerboard, kCharuco };

// A printed target. Board frame: origin at the pattern centre, x along columns, y along rows,
// z = x × y pointing out of the back of the board (away from a camera that sees the print).
struct BoardSpec {
  BoardType type = BoardType::kCheckerboard;
  // checkerboard: inner corners [cols, rows]; charuco: squares [cols, rows].
  int cols = 0;
  int rows = 0;
  double square_size = 0.0;  // metres
  double marker_size = 0.0;  // metres, charuco only
  std::string dictionary;    // charuco only, e.g. "DICT_4X4_50"
  // Physical sheet [width, height] in metres, pattern centred on it; 0 = unknown.
  double board_width = 0.0;
  double board_height = 0.0;

  bool Check(std::string* why) const;
  // Number of squares along x and y.
  int SquaresX() const { return type == BoardType::kCheckerboard ? cols + 1 : cols; }
  int SquaresY() const { return type == BoardType::kCheckerboard ? rows + 1 : rows; }
  // Pattern extent (metres).
  double PatternWidth() const { return SquaresX() * square_size; }
  double PatternHeight() const { return SquaresY() * square_size; }
  // Sheet size if known, else the pattern size.
  double SheetWidth() const { return board_width > 0 ? board_width : PatternWidth(); }
  double SheetHeight() const { return board_height > 0 ? board_height : PatternHeight(); }
};

// The file form of the user's brush: a point in the LiDAR frame near the board centre.
struct LidarSeed {
  Vec3 point = Vec3::Zero();  // metres, LiDAR frame
  double radius = 0.0;        // metres
};

// The board's corner points in the board frame (metres) in detection order: checkerboard inner
// corners row-major (x fastest); ChArUco chessboard corners by id (OpenCV's id order).
std::vector<Vec3> BoardCornerPoints(const BoardSpec& board);

// The pattern square (column i, row j; (0, 0) top left) under a board-frame point (metres),
// clamped to the pattern.
std::pair<int, int> PatternSquareAt(const BoardSpec& board, const Vec2& xy);

// Named printable boards: "a3", "a4" (checkerboards), "charuco-a3", "charuco-a4" (few, large
// squares so that 4x4 markers decode at 3-4 m) and "paper" (Ca²Lib's 8x6 squares of 0.2 m).
// Throws std::invalid_argument naming the known boards for any other name.
BoardSpec BoardPreset(const std::string& name);
// The names BoardPreset knows, in its order.
std::vector<std::string> BoardPresetNames();

}  // namespace calibench
