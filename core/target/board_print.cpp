// BoardPrint: the ink of a checkerboard or an OpenCV ChArUco board as exact rectangles.
#include "core/target/board_print.h"

#include <algorithm>
#include <stdexcept>

#include "core/board/charuco_board.h"

namespace calibench {

BoardPrint::BoardPrint(const BoardSpec& board)
    : board_(board),
      half_sheet_(0.5 * board.SheetWidth(), 0.5 * board.SheetHeight()),
      half_pattern_(0.5 * board.PatternWidth(), 0.5 * board.PatternHeight()) {
  CALIBENCH_CHECK(board.square_size > 0.0 && board.SquaresX() > 0 && board.SquaresY() > 0);
  if (board.type != BoardType::kCharuco) return;
  // OpenCV's own board in metres: its object points are the board frame shifted to the pattern's
  // top-left corner (as BoardCornerPoints uses them), so the markers land where detection and PnP
  // expect them.
  const auto cv_board = MakeCharucoBoard(board, static_cast<float>(board.square_size),
                                         static_cast<float>(board.marker_size));
  const int cells = cv_board->dictionary->markerSize + 2;  // one black border cell per side
  marker_of_square_.assign(static_cast<size_t>(board.SquaresX()) * board.SquaresY(), -1);
  for (size_t k = 0; k < cv_board->ids.size(); ++k) {
    const std::vector<cv::Point3f>& c = cv_board->objPoints[k];
    auto at = [&](int n) { return Vec2(c[n].x - half_pattern_.x(), c[n].y - half_pattern_.y()); };
    Marker marker;
    marker.cells = cells;
    marker.min = at(0).cwiseMin(at(1)).cwiseMin(at(2)).cwiseMin(at(3));
    marker.max = at(0).cwiseMax(at(1)).cwiseMax(at(2)).cwiseMax(at(3));
    marker.ink.assign(static_cast<size_t>(cells * cells), 1);
    cv::Mat image;  // one pixel per cell, border included: 0 = black
    cv_board->dictionary->drawMarker(cv_board->ids[k], cells, image, 1);
    const double cell = (marker.max.x() - marker.min.x()) / cells;
    for (int r = 0; r < cells; ++r) {
      for (int col = 0; col < cells; ++col) {
        // Cell (r, col) of the marker's own image, placed through its corners 0 (top left),
        // 1 (top right) and 3 (bottom left): whatever way OpenCV's frame turns, the ink follows.
        const Vec2 centre =
            at(0) + (col + 0.5) / cells * (at(1) - at(0)) + (r + 0.5) / cells * (at(3) - at(0));
        const int gx =
            std::clamp(static_cast<int>((centre.x() - marker.min.x()) / cell), 0, cells - 1);
        const int gy =
            std::clamp(static_cast<int>((centre.y() - marker.min.y()) / cell), 0, cells - 1);
        marker.ink[static_cast<size_t>(gy * cells + gx)] = image.at<std::uint8_t>(r, col) < 128;
      }
    }
    const auto [i, j] = PatternSquareAt(board, 0.5 * (marker.min + marker.max));
    marker_of_square_[static_cast<size_t>(j * board.SquaresX() + i)] =
        static_cast<int>(markers_.size());
    markers_.push_back(std::move(marker));
  }
}

bool BoardPrint::SquareIsBlack(int i, int j) const {
  if (board_.type == BoardType::kCheckerboard) return (i + j) % 2 == 0;
  // ChArUco: every white square holds a marker; the squares without one are black.
  return marker_of_square_[static_cast<size_t>(j * board_.SquaresX() + i)] < 0;
}

double BoardPrint::Reflectance(const Vec2& xy) const {
  if (std::abs(xy.x()) > half_pattern_.x() || std::abs(xy.y()) > half_pattern_.y()) return 1.0;
  const auto [i, j] = PatternSquareAt(board_, xy);
  if (SquareIsBlack(i, j)) return 0.0;
  if (board_.type == BoardType::kCheckerboard) return 1.0;
  const Marker& m = markers_[marker_of_square_[static_cast<size_t>(j * board_.SquaresX() + i)]];
  if (xy.x() < m.min.x() || xy.x() >= m.max.x() || xy.y() < m.min.y() || xy.y() >= m.max.y())
    return 1.0;
  const double cell = (m.max.x() - m.min.x()) / m.cells;
  const int gx = std::min(static_cast<int>((xy.x() - m.min.x()) / cell), m.cells - 1);
  const int gy = std::min(static_cast<int>((xy.y() - m.min.y()) / cell), m.cells - 1);
  return m.ink[static_cast<size_t>(gy * m.cells + gx)] ? 0.0 : 1.0;
}

std::vector<InkRect> BoardPrint::Ink() const {
  std::vector<InkRect> ink;
  const double s = board_.square_size;
  for (int j = 0; j < board_.SquaresY(); ++j) {
    for (int i = 0; i < board_.SquaresX(); ++i) {
      if (!SquareIsBlack(i, j)) continue;
      const Vec2 min(i * s - half_pattern_.x(), j * s - half_pattern_.y());
      ink.push_back({min, min + Vec2(s, s)});
    }
  }
  for (const Marker& m : markers_) {
    const double cell = (m.max.x() - m.min.x()) / m.cells;
    for (int gy = 0; gy < m.cells; ++gy) {
      for (int gx = 0; gx < m.cells;) {
        if (!m.ink[static_cast<size_t>(gy * m.cells + gx)]) {
          ++gx;
          continue;
        }
        int end = gx;
        while (end < m.cells && m.ink[static_cast<size_t>(gy * m.cells + end)]) ++end;
        ink.push_back(
            {m.min + Vec2(gx * cell, gy * cell), m.min + Vec2(end * cell, (gy + 1) * cell)});
        gx = end;
      }
    }
  }
  return ink;
}

}  // namespace calibench
