// ChessboardEdgeWidthPx (core/target/board_camera.h): how sharp a detected checkerboard's edges
// are, by OpenCV's estimateChessboardSharpness.
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "core/target/board_camera.h"

namespace calibench {

namespace {

// Whether cv::estimateChessboardSharpness has edges to measure in both directions. It maps the
// centres of the squares (col + 0.5, row + 0.5 in squares, one row and column past the corners)
// through the corners' homography and follows the lines between neighbouring centres, skipping the
// first and last line and any line shorter than 10 px or leaving the image; with none left it
// prints "calcEdgeSharpness: checkerboard too small for calculation." on stdout and answers 9999.
// Asked first, the same way (1 px of margin), so that nothing reaches stdout: both directions,
// since OpenCV may turn the board before it measures.
bool SharpnessMeasurable(const std::vector<cv::Point2f>& corners, int cols, int rows, int width,
                         int height) {
  if (cols < 3 || rows < 3) return false;
  std::vector<cv::Point2f> grid;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) grid.emplace_back(static_cast<float>(c), static_cast<float>(r));
  const cv::Mat homography = cv::findHomography(grid, corners);
  if (homography.empty()) return false;
  std::vector<cv::Point2f> squares, centres;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) squares.emplace_back(c + 0.5F, r + 0.5F);
  cv::perspectiveTransform(squares, centres, homography);
  const cv::Rect frame(0, 0, width, height);
  constexpr double kShortestLinePx = 11.0;
  const auto usable = [&](int a, int b) {
    return frame.contains(centres[a]) && frame.contains(centres[b]) &&
           cv::norm(centres[b] - centres[a]) >= kShortestLinePx;
  };
  bool along_rows = false, along_cols = false;
  for (int r = 1; r + 1 < rows && !along_rows; ++r)
    for (int c = 0; c + 1 < cols && !along_rows; ++c)
      along_rows = usable(r * cols + c, r * cols + c + 1);
  for (int c = 1; c + 1 < cols && !along_cols; ++c)
    for (int r = 0; r + 1 < rows && !along_cols; ++r)
      along_cols = usable(r * cols + c, (r + 1) * cols + c);
  return along_rows && along_cols;
}

}  // namespace

std::optional<double> ChessboardEdgeWidthPx(const ImageU8& image, const BoardSpec& board,
                                            const BoardDetection& detection) {
  if (board.type != BoardType::kCheckerboard ||
      static_cast<int>(detection.pixels.size()) != board.cols * board.rows || image.empty())
    return std::nullopt;
  cv::Mat grey;
  const cv::Mat view(image.height, image.width, image.channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<std::uint8_t*>(image.data.data()));
  if (image.channels == 1)
    grey = view;
  else
    cv::cvtColor(view, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> corners;
  for (const Vec2& p : detection.pixels)
    corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  if (!SharpnessMeasurable(corners, board.cols, board.rows, image.width, image.height))
    return std::nullopt;
  // OpenCV measures the edges of one direction per call (horizontal lines by default): a board
  // moved sideways smears only the vertical ones, so both are measured and the wider is kept.
  double widest = 0.0;
  for (const bool vertical : {false, true}) {
    try {
      const cv::Scalar sharpness = cv::estimateChessboardSharpness(
          grey, cv::Size(board.cols, board.rows), corners, 0.8F, vertical);
      // OpenCV answers 9999 when the squares are too small to measure (it prints
      // "checkerboard too small for calculation"): no measurement, not a blurred board.
      constexpr double kOpenCvCannotMeasure = 9999.0;
      if (sharpness[0] > 0 && sharpness[0] < kOpenCvCannotMeasure && std::isfinite(sharpness[0]))
        widest = std::max(widest, sharpness[0]);
    } catch (const cv::Exception&) {
      // An edge OpenCV cannot follow: that direction says nothing.
    }
  }
  if (!(widest > 0)) return std::nullopt;
  return widest;
}

}  // namespace calibench
