// Camera-side board detection: checkerboard (findChessboardCornersSB + cornerSubPix) and ChArUco
// (ArUco markers + interpolateCornersCharuco + offset correction + cornerSubPix).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/board/charuco_board.h"
#include "core/target/board_camera.h"

namespace calibench {

#if defined(__SANITIZE_THREAD__)
namespace {
// ThreadSanitizer cannot see oneTBB's synchronisation (libtbb is not instrumented), so every
// buffer OpenCV hands to its parallel loops would look raced: in a ThreadSanitizer build
// (scripts/sanitize.sh --thread) OpenCV runs them serially, and the races reported are ours.
const int kOpenCvSerialUnderThreadSanitizer = (cv::setNumThreads(0), 0);
}  // namespace
#endif
namespace {

// OpenCV 4.6's interpolateCornersCharuco shifts its own cornerSubPix result by +0.5 px in x and
// y (OpenCV issue 25539). Measured on rendered boards with 18-70 px squares: +0.48 px in x and
// +0.50 px in y over 15 boards, +0.46..+0.51 per board where OpenCV's refinement converges
// (tests/core/target/test_board_detect.cpp, which fails if OpenCV's behaviour changes).
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
// it lands from the full-resolution search (tests/core/target/test_board_detect.cpp).
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

namespace {

// The homography from the spec's grid (column, row of each corner) to the detected pixels;
// empty when there is none, or when the corners do not follow it (out of row order) within a
// fraction of a square, a tolerance that lets lens distortion pass.
cv::Mat GridHomography(const BoardSpec& board, const BoardDetection& detection) {
  std::vector<cv::Point2f> grid, pixels;
  for (std::size_t i = 0; i < detection.ids.size(); ++i) {
    grid.emplace_back(static_cast<float>(detection.ids[i] % board.cols),
                      static_cast<float>(detection.ids[i] / board.cols));
    pixels.emplace_back(static_cast<float>(detection.pixels[i].x()),
                        static_cast<float>(detection.pixels[i].y()));
  }
  const cv::Mat homography = cv::findHomography(grid, pixels);
  if (homography.empty()) return homography;
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(grid, mapped, homography);
  double squared = 0.0;
  for (std::size_t i = 0; i < mapped.size(); ++i) {
    const cv::Point2f d = mapped[i] - pixels[i];
    squared += d.dot(d);
  }
  const double rms = std::sqrt(squared / static_cast<double>(mapped.size()));
  const double square_px = cv::norm(pixels[1] - pixels[0]);
  return rms > 0.15 * square_px ? cv::Mat() : homography;
}

// A square's centre in grid units (half-integers) and the side of the grid it lies on
// (0 left, 1 right, 2 top, 3 bottom).
struct SquareCentre {
  double col = 0.0, row = 0.0;
  int side = 0;
};

// The centres of the ring of squares `k` squares outside the inner corners (k = 0.5: the
// outermost squares).
std::vector<SquareCentre> RingOfSquares(const BoardSpec& board, double k) {
  std::vector<SquareCentre> centres;
  for (double row = -k; row <= board.rows - 1 + k + 1e-9; row += 1.0) {
    centres.push_back({-k, row, 0});
    centres.push_back({board.cols - 1 + k, row, 1});
  }
  for (double col = -k + 1; col <= board.cols - 2 + k + 1e-9; col += 1.0) {
    centres.push_back({col, -k, 2});
    centres.push_back({col, board.rows - 1 + k, 3});
  }
  return centres;
}

// A square's parity: which of the two tones it has.
int Parity(double col, double row) {
  return (static_cast<int>(std::floor(col)) + static_cast<int>(std::floor(row))) & 1;
}

// Whether the squares of a detected checkerboard go on beyond its spec: the ring of square
// centres one square outside the outermost squares is sampled (through the homography from grid
// to image) on each side. On a print of exactly the spec that ring is the white margin or the
// background, one tone; on a larger print it alternates dark and light with the grid's parity.
// The outermost squares, which every print has, teach the two tones and the parity.
bool CheckerboardContinues(const cv::Mat& grey, const BoardSpec& board,
                           const BoardDetection& detection) {
  const cv::Mat homography = GridHomography(board, detection);
  if (homography.empty()) return true;
  // Mean grey of a 3x3 patch at a grid point; -1 outside the image.
  auto sample = [&](double col, double row) {
    std::vector<cv::Point2f> at;
    cv::perspectiveTransform(std::vector<cv::Point2f>{cv::Point2f(col, row)}, at, homography);
    const int x = cvRound(at[0].x), y = cvRound(at[0].y);
    if (x < 1 || y < 1 || x >= grey.cols - 1 || y >= grey.rows - 1) return -1.0;
    return cv::mean(grey(cv::Rect(x - 1, y - 1, 3, 3)))[0];
  };
  double tone_sum[2] = {0, 0}, tone_squares[2] = {0, 0};
  int tone_count[2] = {0, 0};
  for (const SquareCentre& square : RingOfSquares(board, 0.5)) {
    const double value = sample(square.col, square.row);
    if (value < 0) continue;
    const int p = Parity(square.col, square.row);
    tone_sum[p] += value;
    tone_squares[p] += value * value;
    ++tone_count[p];
  }
  if (tone_count[0] == 0 || tone_count[1] == 0) return false;  // the view cuts the board
  const double tone[2] = {tone_sum[0] / tone_count[0], tone_sum[1] / tone_count[1]};
  const double spread =
      std::sqrt(std::max({0.0, tone_squares[0] / tone_count[0] - tone[0] * tone[0],
                          tone_squares[1] / tone_count[1] - tone[1] * tone[1]}));
  const double contrast = std::abs(tone[0] - tone[1]);
  // The outermost squares must alternate in two clear tones. A sub-window of a larger print can
  // come back half a square off its squares (seen with a4's grid on an a3 print at 8 px squares):
  // the samples then land on edges and margins, in no order.
  if (contrast < 20 || contrast < 3 * spread) return true;
  // The ring one square further out, without its corners (a larger print may extend on one side
  // only, so the squares diagonal to the grid's corners may be off it).
  int matches[4] = {0, 0, 0, 0}, seen[4] = {0, 0, 0, 0}, dark[4] = {0, 0, 0, 0};
  const int dark_parity = tone[0] < tone[1] ? 0 : 1;
  for (const SquareCentre& square : RingOfSquares(board, 1.5)) {
    const bool corner = (square.col < -1 || square.col > board.cols) &&
                        (square.row < -1 || square.row > board.rows);
    const double value = corner ? -1 : sample(square.col, square.row);
    if (value < 0) continue;
    const int s = square.side;
    ++seen[s];
    const int p = Parity(square.col, square.row);
    // Its parity's tone, by a clear margin; the white margin of an exact print matches only the
    // light half, the background neither.
    if (std::abs(value - tone[p]) < 0.3 * contrast) {
      ++matches[s];
      dark[s] += p == dark_parity;
    }
  }
  for (int side = 0; side < 4; ++side)
    if (seen[side] >= 3 && dark[side] > 0 && matches[side] >= 0.8 * seen[side]) return true;
  return false;
}

}  // namespace

std::optional<BoardDetection> TrackBoard(const ImageU8& from, const BoardDetection& detection,
                                         const ImageU8& to, double min_tracked_fraction,
                                         std::string* why) {
  std::string local_why;
  if (!why) why = &local_why;
  cv::Mat from_grey, to_grey;
  if (!ToGrey(from, &from_grey, why) || !ToGrey(to, &to_grey, why)) return std::nullopt;
  if (from_grey.size() != to_grey.size()) {
    *why = "the images differ in size";
    return std::nullopt;
  }
  if (detection.pixels.empty()) {
    *why = "no corners to follow";
    return std::nullopt;
  }
  std::vector<cv::Point2f> before, after;
  for (const Vec2& p : detection.pixels)
    before.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  std::vector<unsigned char> status, back_status;
  std::vector<float> error;
  // 21 px window, 3 pyramid levels: follows up to ~80 px of motion, far beyond the stillness
  // thresholds, so a board that moved shows as a changed pose rather than as lost corners. Each
  // corner is followed back as well: a corner that does not come home within half a pixel was
  // not followed (the flow "succeeds" on a blank image too).
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::calcOpticalFlowPyrLK(from_grey, to_grey, before, after, status, error, cv::Size(21, 21), 3,
                           criteria);
  std::vector<cv::Point2f> back;
  cv::calcOpticalFlowPyrLK(to_grey, from_grey, after, back, back_status, error, cv::Size(21, 21), 3,
                           criteria);
  constexpr float kRoundTripPx = 0.5f;
  BoardDetection tracked;
  for (std::size_t i = 0; i < after.size(); ++i) {
    if (!status[i] || !back_status[i] || cv::norm(back[i] - before[i]) > kRoundTripPx ||
        after[i].x < 0 || after[i].y < 0 || after[i].x > to_grey.cols - 1 ||
        after[i].y > to_grey.rows - 1)
      continue;
    tracked.pixels.emplace_back(after[i].x, after[i].y);
    tracked.board_points.push_back(detection.board_points[i]);
    tracked.ids.push_back(detection.ids[i]);
  }
  if (static_cast<double>(tracked.pixels.size()) <
      min_tracked_fraction * static_cast<double>(detection.pixels.size())) {
    *why = "followed " + std::to_string(tracked.pixels.size()) + " of " +
           std::to_string(detection.pixels.size()) + " corners";
    return std::nullopt;
  }
  return tracked;
}

BoardFit FitBoard(const ImageU8& image, const BoardSpec& board) {
  std::string why;
  const std::optional<BoardDetection> detection =
      DetectBoard(image, board, BoardDetectionOptions{}, &why);
  if (!detection) return BoardFit::kNotFound;
  cv::Mat grey;
  if (!ToGrey(image, &grey, &why)) return BoardFit::kNotFound;
  if (board.type == BoardType::kCheckerboard)
    return CheckerboardContinues(grey, board, *detection) ? BoardFit::kPartOfLarger
                                                          : BoardFit::kFits;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryByName(board.dictionary);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  cv::aruco::detectMarkers(grey, dictionary, marker_corners, marker_ids, parameters);
  // A ChArUco board of cols x rows squares carries markers 0 .. cols*rows/2 - 1.
  const int markers = board.cols * board.rows / 2;
  for (int id : marker_ids)
    if (id >= markers) return BoardFit::kPartOfLarger;
  return BoardFit::kFits;
}

}  // namespace calibench
