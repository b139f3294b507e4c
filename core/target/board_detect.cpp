// Camera-side board detection: checkerboard (findChessboardCornersSB + cornerSubPix) and ChArUco
// (ArUco markers + interpolateCornersCharuco + offset correction + cornerSubPix).
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/target/board_camera.h"
#include "core/target/charuco_board.h"

namespace calibench {
namespace {

// OpenCV 4.6's interpolateCornersCharuco shifts its own cornerSubPix result by +0.5 px in x and
// y (OpenCV issue 25539). Measured on rendered boards with 18-70 px squares: +0.48 px in x and
// +0.50 px in y over 15 boards, +0.46..+0.51 per board where OpenCV's refinement converges
// (tests/core/test_board_detect.cpp, which fails if OpenCV's behaviour changes).
constexpr double kCharucoOffsetPx = 0.5;

// cornerSubPix half window for checkerboards, as a fraction of the smallest corner spacing: half
// a square keeps the window inside the four squares that meet at the corner. Measured on 15
// rendered boards (5-27 px squares): 0.5 gives 0.068 px RMS, 0.3 gives 0.083 px, 0.2 0.094 px.
constexpr double kCheckerWindowFraction = 0.5;
constexpr int kMinSubpixHalfWindow = 2;
constexpr int kMaxSubpixHalfWindow = 11;

bool ToGrey(const ImageU8& image, cv::Mat* grey, std::string* why) {
  if (image.empty() || image.width <= 0 || image.height <= 0) {
    *why = "empty image";
    return false;
  }
  if (image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
    *why = "image buffer size does not match its width, height and channels";
    return false;
  }
  // The cv::Mat header wraps the buffer without copying; cvtColor writes a new matrix.
  const int type = CV_MAKETYPE(CV_8U, image.channels);
  const cv::Mat wrapped(image.height, image.width, type,
                        const_cast<std::uint8_t*>(image.data.data()));
  switch (image.channels) {
    case 1:
      *grey = wrapped.clone();
      return true;
    case 3:
      cv::cvtColor(wrapped, *grey, cv::COLOR_BGR2GRAY);
      return true;
    case 4:
      cv::cvtColor(wrapped, *grey, cv::COLOR_BGRA2GRAY);
      return true;
    default:
      *why = "unsupported image with " + std::to_string(image.channels) + " channels";
      return false;
  }
}

// Grid position (column, row) of corner `id`: row-major, x fastest, `grid_cols` per row.
cv::Point GridCell(int id, int grid_cols) { return {id % grid_cols, id / grid_cols}; }

// Smallest image distance between grid-adjacent detected corners (pixels).
double MinCornerSpacing(const std::vector<cv::Point2f>& corners, const std::vector<int>& ids,
                        int grid_cols) {
  double spacing = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < corners.size(); ++i) {
    for (size_t j = i + 1; j < corners.size(); ++j) {
      const cv::Point a = GridCell(ids[i], grid_cols);
      const cv::Point b = GridCell(ids[j], grid_cols);
      if (std::abs(a.x - b.x) + std::abs(a.y - b.y) != 1) continue;
      spacing = std::min(spacing, static_cast<double>(cv::norm(corners[i] - corners[j])));
    }
  }
  return spacing;
}

// `window_fraction` of the smallest corner spacing, unless the options fix the half window.
void RefineCorners(const cv::Mat& grey, const std::vector<int>& ids, int grid_cols,
                   double window_fraction, const BoardDetectionOptions& options,
                   std::vector<cv::Point2f>* corners) {
  int half = options.subpix_half_window_px;
  if (half <= 0) {
    const double spacing = MinCornerSpacing(*corners, ids, grid_cols);
    half = std::isfinite(spacing) ? static_cast<int>(std::floor(window_fraction * spacing))
                                  : kMinSubpixHalfWindow;
    half = std::clamp(half, kMinSubpixHalfWindow, kMaxSubpixHalfWindow);
  }
  // A tight epsilon: the default 0.1 px stopping step would leave a good part of the error.
  const cv::TermCriteria criteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4);
  const std::vector<cv::Point2f> start = *corners;
  cv::cornerSubPix(grey, *corners, cv::Size(half, half), cv::Size(-1, -1), criteria);
  // A corner that wanders off by more than the half window has locked onto other structure
  // (blur, glare, a marker): keep the detector's position for it.
  for (size_t i = 0; i < corners->size(); ++i) {
    if (cv::norm((*corners)[i] - start[i]) > half) (*corners)[i] = start[i];
  }
}

BoardDetection MakeDetection(const BoardSpec& board, const std::vector<cv::Point2f>& corners,
                             const std::vector<int>& ids) {
  const std::vector<Vec3> points = BoardCornerPoints(board);
  BoardDetection detection;
  for (size_t i = 0; i < corners.size(); ++i) {
    CALIBENCH_CHECK(ids[i] >= 0 && ids[i] < static_cast<int>(points.size()));
    detection.pixels.emplace_back(corners[i].x, corners[i].y);
    detection.board_points.push_back(points[ids[i]]);
    detection.ids.push_back(ids[i]);
  }
  return detection;
}

// Pyramid levels (each a 2x pyrDown of the one before) the checkerboard search may start from:
// the coarsest whose shorter side keeps at least this many pixels. On the real 1920 x 1208 fisheye
// set the board (47-59 px squares) is found on every image at level 2 (480 x 302) in 32 ms, against
// 721 ms at full resolution; cornerSubPix at full resolution then lands within 0.0002 px of where
// it lands from the full-resolution search (tests/core/test_board_detect.cpp).
constexpr int kMinSearchSidePx = 240;
constexpr int kMaxPyramidLevel = 3;

// Levels [0, n): level 0 is `grey` itself (shared, not copied).
std::vector<cv::Mat> SearchPyramid(const cv::Mat& grey) {
  std::vector<cv::Mat> levels{grey};
  while (static_cast<int>(levels.size()) <= kMaxPyramidLevel &&
         std::min(levels.back().cols, levels.back().rows) / 2 >= kMinSearchSidePx) {
    cv::Mat down;
    cv::pyrDown(levels.back(), down);
    levels.push_back(std::move(down));
  }
  return levels;
}

// The board's corners found on the coarsest pyramid level that shows it, in full-resolution
// pixels (pyrDown samples the even pixels, so x_full = 2^level * x_level). The exhaustive,
// upsampled search finds more boards (small, tilted squares) but takes about four times longer
// than the fast one at full resolution; it runs last, and only there.
bool FindCheckerboard(const cv::Mat& grey, const cv::Size& pattern, bool pyramid,
                      std::vector<cv::Point2f>* corners) {
  const std::vector<cv::Mat> levels = pyramid ? SearchPyramid(grey) : std::vector<cv::Mat>{grey};
  for (int level = static_cast<int>(levels.size()) - 1; level >= 0; --level) {
    if (!cv::findChessboardCornersSB(levels[level], pattern, *corners,
                                     cv::CALIB_CB_NORMALIZE_IMAGE))
      continue;
    const float scale = static_cast<float>(1 << level);
    for (cv::Point2f& c : *corners) c *= scale;
    return true;
  }
  const int flags = cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY | cv::CALIB_CB_NORMALIZE_IMAGE;
  return cv::findChessboardCornersSB(grey, pattern, *corners, flags);
}

std::optional<BoardDetection> DetectCheckerboard(const cv::Mat& grey, const BoardSpec& board,
                                                 const BoardDetectionOptions& options,
                                                 std::string* why) {
  const std::string name = std::to_string(board.cols) + "x" + std::to_string(board.rows);
  const cv::Size pattern(board.cols, board.rows);
  std::vector<cv::Point2f> corners;
  // cornerSubPix below converges to the same point from any level's start.
  const bool found = FindCheckerboard(grey, pattern, options.pyramid_search, &corners);
  if (!found || static_cast<int>(corners.size()) != board.cols * board.rows) {
    *why = "chessboard " + name + " not found";
    return std::nullopt;
  }
  if (static_cast<int>(corners.size()) < options.min_corners) {
    *why = "chessboard " + name + " has " + std::to_string(corners.size()) + " corners (need " +
           std::to_string(options.min_corners) + ")";
    return std::nullopt;
  }
  std::vector<int> ids(corners.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
  RefineCorners(grey, ids, board.cols, kCheckerWindowFraction, options, &corners);
  return MakeDetection(board, corners, ids);
}

std::optional<BoardDetection> DetectCharuco(const cv::Mat& grey, const BoardSpec& board,
                                            const BoardDetectionOptions& options,
                                            std::string* why) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryByName(board.dictionary);
  if (!dictionary) {
    *why = "unknown ArUco dictionary '" + board.dictionary + "'";
    return std::nullopt;
  }
  const cv::Ptr<cv::aruco::CharucoBoard> charuco =
      cv::aruco::CharucoBoard::create(board.cols, board.rows, static_cast<float>(board.square_size),
                                      static_cast<float>(board.marker_size), dictionary);

  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  parameters->minMarkerPerimeterRate = options.min_marker_perimeter_rate;
  std::vector<std::vector<cv::Point2f>> rejected;
  cv::aruco::detectMarkers(grey, dictionary, marker_corners, marker_ids, parameters, rejected);
  // Markers the first pass missed but the board layout predicts.
  cv::aruco::refineDetectedMarkers(grey, charuco, marker_corners, marker_ids, rejected);
  if (marker_ids.empty()) {
    *why = "no " + board.dictionary + " markers found";
    return std::nullopt;
  }
  // No camera matrix: the local-homography path, which needs no intrinsics and is what the offset
  // constant above was measured on.
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco, corners, ids);
  if (static_cast<int>(corners.size()) < options.min_corners) {
    *why = "only " + std::to_string(corners.size()) + " ChArUco corners (need " +
           std::to_string(options.min_corners) + ")";
    return std::nullopt;
  }
  // Without the correction, OpenCV's corners are returned as they are (to compare against): our
  // own refinement would converge to the saddle point and remove the offset by itself.
  if (options.correct_charuco_offset) {
    for (cv::Point2f& c : corners) c -= cv::Point2f(kCharucoOffsetPx, kCharucoOffsetPx);
    // OpenCV's window (distance to the nearest marker corner - 2 px, at least 1 px) is often
    // too small to converge at small squares; ours spans the marker-free margin around the corner,
    // (square - marker) / 2, which leaves the marker borders out of the window.
    const double margin_fraction =
        0.5 * (board.square_size - board.marker_size) / board.square_size;
    RefineCorners(grey, ids, board.cols - 1, margin_fraction, options, &corners);
  }
  return MakeDetection(board, corners, ids);
}

}  // namespace

bool BoardDetectionOptions::Check(std::string* why) const {
  if (subpix_half_window_px < 0) {
    *why = "subpix_half_window_px must be >= 0 (0 = from the square size)";
    return false;
  }
  if (min_corners < 4) {
    *why = "min_corners must be >= 4 (a planar pose needs 4 corners)";
    return false;
  }
  if (!(min_marker_perimeter_rate > 0 && min_marker_perimeter_rate < 1)) {
    *why = "min_marker_perimeter_rate must be in (0, 1) (fraction of the larger image side)";
    return false;
  }
  return true;
}

std::optional<BoardDetection> DetectBoard(const ImageU8& image, const BoardSpec& board,
                                          const BoardDetectionOptions& options, std::string* why) {
  std::string local_why;
  if (!why) why = &local_why;
  if (!options.Check(why) || !board.Check(why)) return std::nullopt;
  cv::Mat grey;
  if (!ToGrey(image, &grey, why)) return std::nullopt;
  return board.type == BoardType::kCheckerboard ? DetectCheckerboard(grey, board, options, why)
                                                : DetectCharuco(grey, board, options, why);
}

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
  // OpenCV measures the edges of one direction per call (horizontal lines by default): a board
  // moved sideways smears only the vertical ones, so both are measured and the wider is kept.
  double widest = 0.0;
  for (const bool vertical : {false, true}) {
    try {
      const cv::Scalar sharpness = cv::estimateChessboardSharpness(
          grey, cv::Size(board.cols, board.rows), corners, 0.8F, vertical);
      if (sharpness[0] > 0 && std::isfinite(sharpness[0])) widest = std::max(widest, sharpness[0]);
    } catch (const cv::Exception&) {
      // An edge OpenCV cannot follow: that direction says nothing.
    }
  }
  if (!(widest > 0)) return std::nullopt;
  return widest;
}

}  // namespace calibench
