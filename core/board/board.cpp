#include "core/board/board.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/board/charuco_board.h"

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

std::pair<int, int> PatternSquareAt(const BoardSpec& board, const Vec2& xy) {
  const double half_width = 0.5 * board.PatternWidth(), half_height = 0.5 * board.PatternHeight();
  const int i = std::clamp(static_cast<int>(std::floor((xy.x() + half_width) / board.square_size)),
                           0, board.SquaresX() - 1);
  const int j = std::clamp(static_cast<int>(std::floor((xy.y() + half_height) / board.square_size)),
                           0, board.SquaresY() - 1);
  return {i, j};
}

namespace {

// Printable boards by name. ChArUco: few, large squares, so that 4x4 markers stay decodable
// (> ~12 px) at 3-4 m. "paper": Ca²Lib Section 4.1, 8x6 squares of 0.2 m printed edge to edge.
struct NamedBoard {
  const char* name;
  BoardType type;
  int cols, rows;        // inner corners (checkerboard) or squares (ChArUco)
  double square_size;    // metres
  double marker_size;    // metres, ChArUco only
  double width, height;  // the sheet, metres
};
constexpr NamedBoard kNamedBoards[] = {
    {"a3", BoardType::kCheckerboard, 7, 5, 0.04, 0.0, 0.42, 0.297},
    {"a4", BoardType::kCheckerboard, 5, 4, 0.035, 0.0, 0.297, 0.21},
    {"charuco-a3", BoardType::kCharuco, 6, 4, 0.065, 0.05, 0.42, 0.297},
    {"charuco-a4", BoardType::kCharuco, 5, 3, 0.055, 0.042, 0.297, 0.21},
    {"paper", BoardType::kCheckerboard, 7, 5, 0.2, 0.0, 1.6, 1.2}};

}  // namespace

BoardSpec BoardPreset(const std::string& name) {
  for (const NamedBoard& named : kNamedBoards) {
    if (name != named.name) continue;
    BoardSpec board;
    board.type = named.type;
    board.cols = named.cols;
    board.rows = named.rows;
    board.square_size = named.square_size;
    board.marker_size = named.marker_size;
    if (named.type == BoardType::kCharuco) board.dictionary = "DICT_4X4_50";
    board.board_width = named.width;
    board.board_height = named.height;
    return board;
  }
  std::string known;
  for (const std::string& n : BoardPresetNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown board '" + name + "' (known: " + known + ")");
}

std::vector<std::string> BoardPresetNames() {
  std::vector<std::string> names;
  for (const NamedBoard& named : kNamedBoards) names.emplace_back(named.name);
  return names;
}

}  // namespace calibench
