// BoardPrint, the one pattern renderer: its exact ink agrees with OpenCV's own drawing of the same
// ChArUco board, and a print rendered from it is detected with the right marker ids.
#include <gtest/gtest.h>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include "core/board/charuco_board.h"
#include "core/target/board_print.h"

namespace calibench {
namespace {

constexpr int kPixelsPerSquare = 120;

// Our reflectance sampled at pixel centres of an image of the pattern alone (as OpenCV draws it).
cv::Mat RenderPattern(const BoardPrint& print) {
  const BoardSpec& b = print.board();
  cv::Mat image(b.SquaresY() * kPixelsPerSquare, b.SquaresX() * kPixelsPerSquare, CV_8UC1);
  const double metres_per_pixel = b.square_size / kPixelsPerSquare;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const Vec2 xy((c + 0.5) * metres_per_pixel - 0.5 * b.PatternWidth(),
                    (r + 0.5) * metres_per_pixel - 0.5 * b.PatternHeight());
      image.at<std::uint8_t>(r, c) = print.Reflectance(xy) > 0.5 ? 255 : 0;
    }
  }
  return image;
}

BoardSpec Charuco(int cols, int rows, double square, double marker, const std::string& dict) {
  BoardSpec b;
  b.type = BoardType::kCharuco;
  b.cols = cols, b.rows = rows, b.square_size = square, b.marker_size = marker;
  b.dictionary = dict;
  return b;
}

TEST(BoardPrint, CharucoInkIsOpenCvsBoard) {
  for (const BoardSpec& board :
       {BoardPreset("charuco-a3"), BoardPreset("charuco-a4"),
        Charuco(5, 7, 0.04, 0.03, "DICT_5X5_100"), Charuco(8, 6, 0.03, 0.021, "DICT_6X6_250")}) {
    const BoardPrint print(board);
    const cv::Mat ours = RenderPattern(print);
    const auto cv_board =
        MakeCharucoBoard(board, 1.0f, static_cast<float>(board.marker_size / board.square_size));
    cv::Mat theirs;
    cv_board->draw(ours.size(), theirs, 0, 1);
    cv::Mat differ;
    cv::compare(ours, theirs > 127, differ, cv::CMP_NE);
    // Only OpenCV's own rounding of marker edges to its pixel grid may differ (a pixel or two
    // along an edge); a wrong cell (~15 px) or square would survive an opening by 5 x 5.
    const double fraction = cv::countNonZero(differ) / static_cast<double>(ours.total());
    EXPECT_LT(fraction, 0.03) << board.dictionary << " " << board.cols << "x" << board.rows;
    cv::morphologyEx(differ, differ, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
    EXPECT_EQ(cv::countNonZero(differ), 0)
        << board.dictionary << " " << board.cols << "x" << board.rows;
    // Its markers decode with the board's ids, every one.
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::Mat padded;
    cv::copyMakeBorder(ours, padded, 40, 40, 40, 40, cv::BORDER_CONSTANT, 255);
    cv::aruco::detectMarkers(padded, cv_board->dictionary, corners, ids);
    std::sort(ids.begin(), ids.end());
    std::vector<int> expected = cv_board->ids;
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(ids, expected);
  }
}

TEST(BoardPrint, InkCoversExactlyTheBlackArea) {
  for (const BoardSpec& board : {BoardPreset("a4"), BoardPreset("charuco-a4")}) {
    const BoardPrint print(board);
    double ink_area = 0.0;
    for (const InkRect& r : print.Ink()) ink_area += (r.max - r.min).prod();
    const cv::Mat image = RenderPattern(print);
    const double black_area = (image.total() - cv::countNonZero(image)) *
                              std::pow(board.square_size / kPixelsPerSquare, 2);
    EXPECT_NEAR(ink_area, black_area, 0.01 * black_area);
    for (const InkRect& r : print.Ink()) {
      EXPECT_EQ(print.Reflectance(0.5 * (r.min + r.max)), 0.0);
    }
  }
  // A checkerboard of 6 x 5 squares has 15 black ones, (0, 0) among them.
  const BoardPrint checker(BoardPreset("a4"));
  EXPECT_EQ(checker.Ink().size(), 15u);
  EXPECT_EQ(checker.Reflectance(Vec2(-0.10, -0.08)), 0.0);
}

}  // namespace
}  // namespace calibench
