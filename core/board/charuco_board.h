// OpenCV's ChArUco board for a BoardSpec: one place that names the dictionaries. Internal to the
// .cpp files of core/target and core/sim (it pulls in OpenCV's aruco headers).
#pragma once

#include <opencv2/aruco/charuco.hpp>
#include <string>

#include "core/board/board.h"

namespace calibench {

// The predefined dictionary called `name` (e.g. "DICT_4X4_50"); nullptr when there is none.
cv::Ptr<cv::aruco::Dictionary> DictionaryByName(const std::string& name);

// OpenCV 4.6's board with the given square and marker lengths; its frame has x right and y down
// on the drawn image, origin at the top-left corner of the pattern (measured, see test_sim.cpp).
// Throws std::invalid_argument for an unknown dictionary.
cv::Ptr<cv::aruco::CharucoBoard> MakeCharucoBoard(const BoardSpec& board, float square_length,
                                                  float marker_length);

}  // namespace calibench
