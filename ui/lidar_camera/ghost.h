// The board sheet as the camera view draws it, the detected board and the ghost board (where
// `advise` says to hold it next) alike: its outline in image pixels.
#pragma once

#include <vector>

#include "core/board/board.h"
#include "core/camera/camera.h"

namespace calibench::ui {

// The sheet's outline through `camera` (edges subdivided into `steps` pieces: lenses bend them),
// starting at each corner in turn: (-w/2, -h/2), (w/2, -h/2), (w/2, h/2), (-w/2, h/2) in the
// board frame (BoardSpec's, origin at the sheet centre). Points behind the camera are left out.
std::vector<Vec2> SheetOutlinePixels(const CameraModel& camera, const BoardSpec& board,
                                     const Pose& cam_from_board, int steps = 16);

}  // namespace calibench::ui
