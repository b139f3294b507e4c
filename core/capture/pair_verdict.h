// The camera side of one try of the pair finder (core/capture/recording_pairs.h), on its own: the
// board searched for in the pair's image, its corners followed into the window's other images
// (the board held still?), its pose compared with the pairs kept (a near-duplicate?).
#pragma once

#include <functional>
#include <map>
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
  bool moving = false;                 // dropped because the board moved between the images
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
  int searched = 0, found = 0;    // images searched for the board, and of those, found in
  bool camera_still = false;      // a moving try whose frames show the board still
  bool camera_moving = false;     // a still try whose images show the board move
};
// `decoded`: the try's image when already decoded. Throws IoError naming `source` when the
// images contradict the intrinsics (another size).
TryOutcome JudgeTry(const recording_detail::Try& attempt, std::optional<ImageU8> decoded,
                    const PairTopics& topics, const BoardSpec& board, const std::vector<Pose>& kept,
                    const PairSelectionOptions& options, const std::string& source);

// The board's search in each frame of a moving capture, kept while the sweeps around the frame
// are tried: a frame lies around several sweeps and is searched once (the pair finder's worker's).
class FrameSearches {
 public:
  struct Search {
    std::optional<Pose> cam_from_board;  // nullopt: the board not found (or the frame unreadable)
    ImageU8 image;                       // the frame, where the board was found
    bool handed_out = false;             // a pair has taken its pixels
  };
  // The search of `frame`, made now when it was not made before (*searched_now then true).
  const Search& Of(const recording_detail::StampedBytes& frame, const PairTopics& topics,
                   const CameraModel& camera, const BoardSpec& board, const LoadLimits& limits,
                   const std::string& source, bool* searched_now);
  // The frame's pixels the first time a pair takes it (empty after: the earlier pair's writer
  // has them).
  ImageU8 HandOut(std::int64_t stamp_ns);
  // The frame's pixels, handed out or not (a still pair's image).
  ImageU8 Pixels(std::int64_t stamp_ns) const;
  // Forgets the frames stamped before `oldest_ns` (no sweep left to try reaches them).
  void Forget(std::int64_t oldest_ns);

 private:
  std::map<std::int64_t, Search> searches_;
};

// A moving sweep's try (recording_detail::Try::moving): the board in each frame around it, the
// frames where it is found kept as the pair's (the camera's track of the board), then the sweep
// decoded. Where the camera saw the board still in every frame (a hold, where something else
// moved before the LiDAR), a still pair of the nearest frame, if it is no near-duplicate of
// `kept`. Throws IoError naming `source` when the images contradict the intrinsics.
TryOutcome JudgeMovingTry(const recording_detail::Try& attempt, const PairTopics& topics,
                          const BoardSpec& board, const std::vector<Pose>& kept,
                          const PairSelectionOptions& options, const std::string& source,
                          FrameSearches* searches);

}  // namespace calibench
