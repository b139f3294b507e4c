#include "core/target/board.h"

#include <stdexcept>

#include "core/target/charuco_board.h"

namespace calibench {

bool BoardSpec::Check(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  const int min_count = type == BoardType::kCheckerboard ? 2 : 3;
  if (cols < min_count || rows < min_count)
    return fail(type == BoardType::kCheckerboard ? "inner_corners must be at least [2, 2]"
                                                 : "squares must be at least [3, 3]");
  if (!(square_size > 0)) return fail("square_size must be > 0 (metres)");
  if (type == BoardType::kCharuco) {
    if (!(marker_size > 0 && marker_size < square_size))
      return fail("marker_size must be > 0 and smaller than square_size");
    if (dictionary.empty()) return fail("charuco needs a dictionary such as DICT_4X4_50");
  }
  if (board_width < 0 || board_height < 0) return fail("board_size must be positive");
  if (board_width > 0 &&
      (board_width + 1e-9 < PatternWidth() || board_height + 1e-9 < PatternHeight()))
    return fail("board_size is smaller than the printed pattern");
  return true;
}

cv::Ptr<cv::aruco::Dictionary> DictionaryByName(const std::string& name) {
  static const std::pair<const char*, cv::aruco::PREDEFINED_DICTIONARY_NAME> kNames[] = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11}};
  for (const auto& [text, id] : kNames) {
    if (name == text) return cv::aruco::getPredefinedDictionary(id);
  }
  return nullptr;
}

cv::Ptr<cv::aruco::CharucoBoard> MakeCharucoBoard(const BoardSpec& board, float square_length,
                                                  float marker_length) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryByName(board.dictionary);
  if (!dictionary)
    throw std::invalid_argument("unknown ArUco dictionary '" + board.dictionary + "'");
  try {
    return cv::aruco::CharucoBoard::create(board.cols, board.rows, square_length, marker_length,
                                           dictionary);
  } catch (const cv::Exception& e) {
    throw std::invalid_argument("cannot build the ChArUco board: " + std::string(e.what()));
  }
}

std::vector<Vec3> BoardCornerPoints(const BoardSpec& board) {
  const double half_w = 0.5 * board.PatternWidth(), half_h = 0.5 * board.PatternHeight();
  const double s = board.square_size;
  std::vector<Vec3> points;
  if (board.type == BoardType::kCheckerboard) {
    for (int j = 0; j < board.rows; ++j) {
      for (int i = 0; i < board.cols; ++i) {
        points.emplace_back((i + 1) * s - half_w, (j + 1) * s - half_h, 0.0);
      }
    }
    return points;
  }
  // A unit-square OpenCV board gives exact integer corner coordinates in OpenCV's id order.
  const auto cv_board = MakeCharucoBoard(board, 1.0f, 0.5f);
  for (const cv::Point3f& c : cv_board->chessboardCorners) {
    points.emplace_back(c.x * s - half_w, c.y * s - half_h, 0.0);
  }
  return points;
}

BoardSpec BoardPreset(const std::string& name) {
  BoardSpec b;
  if (name == "a3" || name == "a4") {
    const bool a3 = name == "a3";
    b.type = BoardType::kCheckerboard;
    b.cols = a3 ? 7 : 5;
    b.rows = a3 ? 5 : 4;
    b.square_size = a3 ? 0.04 : 0.035;
    b.board_width = a3 ? 0.42 : 0.297;
    b.board_height = a3 ? 0.297 : 0.21;
  } else if (name == "charuco-a3" || name == "charuco-a4") {
    const bool a3 = name == "charuco-a3";
    // Few, large squares: 4x4 markers must stay decodable (> ~12 px) at 3-4 m.
    b.type = BoardType::kCharuco;
    b.cols = a3 ? 6 : 5;
    b.rows = a3 ? 4 : 3;
    b.square_size = a3 ? 0.065 : 0.055;
    b.marker_size = a3 ? 0.05 : 0.042;
    b.dictionary = "DICT_4X4_50";
    b.board_width = a3 ? 0.42 : 0.297;
    b.board_height = a3 ? 0.297 : 0.21;
  } else if (name == "paper") {
    // Ca²Lib Section 4.1: 8x6 squares of 0.2 m (7x5 inner corners) printed edge to edge.
    b.type = BoardType::kCheckerboard;
    b.cols = 7;
    b.rows = 5;
    b.square_size = 0.2;
    b.board_width = 1.6;
    b.board_height = 1.2;
  } else {
    throw std::invalid_argument("unknown board '" + name +
                                "' (known: a3, a4, charuco-a3, charuco-a4, paper)");
  }
  return b;
}

}  // namespace calibench
