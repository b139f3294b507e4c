// The camera side of one try of the pair finder (core/capture/recording_pairs.h), on its own: the
// board searched for in the pair's image, its corners followed into the window's other images
// (the board held still?), its pose compared with the pairs kept (a near-duplicate?).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/capture/recording_pairs.h"
#include "core/capture/recording_try.h"

namespace calibench {

// "200 ms": a duration in the drop reasons.
std::string MillisecondsText(double seconds);

struct CameraVerdict {
  std::optional<Pose> cam_from_board;  // set when the try gives a pair
  std::string dropped;                 // why not, otherwise
  bool searched = false;               // the board was searched for (the image was readable)
  bool found = false;                  // and found
  bool stillness_checked = false;      // another image of the window was there to compare
};

// `other_image(i)` decodes the window's i-th other image (nullopt: unreadable, skipped); it is
// called only while the verdict is still open.
CameraVerdict JudgeCameraSide(const ImageU8& image, std::size_t others,
                              const std::function<std::optional<ImageU8>(std::size_t)>& other_image,
                              const CameraModel& camera, const BoardSpec& board,
                              const std::vector<Pose>& kept, const PairSelectionOptions& options);

// The image of a try's message (Image or CompressedImage, as `topics` says); throws
// std::invalid_argument when it cannot be decoded.
ImageU8 DecodeTryMessageImage(const recording_detail::StampedBytes& image, const PairTopics& topics,
                              const LoadLimits& limits);

// One try searched with the board known: the camera's verdict, then the sweep decoded.
struct TryOutcome {
  std::optional<FoundPair> pair;  // set when the try gives a pair
  std::string dropped;            // why not, otherwise
  bool searched = false, found = false;
};
// `decoded`: the try's image when already decoded. Throws IoError naming `source` when the
// images contradict the intrinsics (another size).
TryOutcome JudgeTry(const recording_detail::Try& attempt, std::optional<ImageU8> decoded,
                    const PairTopics& topics, const BoardSpec& board, const std::vector<Pose>& kept,
                    const PairSelectionOptions& options, const std::string& source);

}  // namespace calibench
