#include "core/capture/pair_verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "core/geometry/geometry.h"
#include "core/recording/ros_messages.h"
#include "core/target/board_camera.h"

namespace calibench {

namespace {

// Corners that must be followed into an image of the window for it to count as seen.
constexpr double kMinTrackedFraction = 0.8;

// A checkerboard's corners may come back in either of two orders, 180 degrees apart about its
// normal (the pattern looks the same turned over): one board pose, two rotations. The origin,
// at the pattern's centre, is the same for both.
PoseError BoardPoseError(const Pose& a, const Pose& b, const BoardSpec& board) {
  PoseError error = ComputePoseError(a, b);
  if (board.type != BoardType::kCheckerboard) return error;
  Pose turned = b;
  turned.linear() = b.rotation() * Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  error.rotation_rad = std::min(error.rotation_rad, ComputePoseError(a, turned).rotation_rad);
  return error;
}

bool Within(const PoseError& error, double translation_m, double rotation_deg) {
  return error.translation_m <= translation_m && error.rotation_rad * kRadToDeg <= rotation_deg;
}

// The camera's view of the board in `other` agrees with `pose`: its corners followed there give
// a pose within the stillness thresholds.
bool StillIn(const ImageU8& image, const BoardDetection& detection, const ImageU8& other,
             const CameraModel& camera, const Pose& pose, const PairSelectionOptions& options) {
  std::string why;
  const auto tracked = TrackBoard(image, detection, other, kMinTrackedFraction, &why);
  if (!tracked) return false;
  const auto observation = EstimateBoardPose(camera, *tracked, PnpOptions{}, &why);
  return observation && Within(ComputePoseError(observation->cam_from_board, pose),
                               options.still_translation_m, options.still_rotation_deg);
}

}  // namespace

std::string MillisecondsText(double seconds) {
  return std::to_string(static_cast<int>(std::lround(seconds * 1000))) + " ms";
}
namespace {

// A still hold's other sweeps appended to the tried one (returns and intensities; a ring-less
// cloud has no rings to keep; each return's time after the tried sweep's stamp, `stamp_ns`), as
// long as the cloud stays within the load limit. An unreadable sweep among them is left out.
void IntegrateSweeps(const std::vector<recording_detail::StampedBytes>& sweeps,
                     const PairTopics& topics, const LoadLimits& limits, std::int64_t stamp_ns,
                     LidarCloud* cloud) {
  for (const recording_detail::StampedBytes& sweep : sweeps) {
    LidarCloud more;
    try {
      more = DecodeCloudMessage(*sweep.bytes, topics.livox_cloud, topics.cloud, limits).cloud;
    } catch (const std::invalid_argument&) {
      continue;
    }
    if (more.HasRing() || cloud->HasRing() ||
        static_cast<std::int64_t>(cloud->size() + more.size()) > limits.max_cloud_points)
      continue;
    const bool intensity = cloud->HasIntensity() && more.HasIntensity();
    if (!intensity) cloud->intensity.clear();
    // Viewpoints are kept only when every sweep has them: a ray without its own start would
    // be taken to start at the origin.
    const bool viewpoint = cloud->HasViewpoint() && more.HasViewpoint();
    if (viewpoint)
      cloud->viewpoint.insert(cloud->viewpoint.end(), more.viewpoint.begin(), more.viewpoint.end());
    else
      cloud->viewpoint.clear();
    // Times only when every sweep has them: a return without one would pass for the stamp's.
    if (cloud->HasTime() && more.HasTime()) {
      const float shift = static_cast<float>((sweep.stamp_ns - stamp_ns) * 1e-9);
      for (const float t : more.time_s) cloud->time_s.push_back(t + shift);
    } else {
      cloud->time_s.clear();
    }
    cloud->points.insert(cloud->points.end(), more.points.begin(), more.points.end());
    if (intensity)
      cloud->intensity.insert(cloud->intensity.end(), more.intensity.begin(), more.intensity.end());
    cloud->range.clear();
  }
  cloud->width = static_cast<int>(cloud->size());
  cloud->height = 1;
}

// The try's sweep (and a ring-less hold's others) into `pair`; false with *dropped set when it
// cannot be read or holds no point.
bool DecodeTryCloud(const recording_detail::Try& attempt, const PairTopics& topics,
                    const LoadLimits& limits, FoundPair* pair, std::string* dropped) {
  try {
    CloudMessage message =
        DecodeCloudMessage(*attempt.cloud.bytes, topics.livox_cloud, topics.cloud, limits);
    pair->cloud = std::move(message.cloud);
    pair->point_times = std::move(message.point_times);
    IntegrateSweeps(attempt.integrated, topics, limits, attempt.cloud.stamp_ns, &pair->cloud);
  } catch (const std::invalid_argument&) {
    *dropped = "cloud message unreadable";
    return false;
  }
  if (pair->cloud.size() == 0) {
    *dropped = "cloud has no finite point";
    return false;
  }
  return true;
}

// The images must be the intrinsics' size: a recording that says otherwise is refused whole.
void CheckImageSize(const ImageU8& image, const CameraModel& camera, const PairTopics& topics,
                    const std::string& source) {
  if (camera.width != image.width || camera.height != image.height)
    throw IoError(source + ": the images on " + topics.image_topic + " are " +
                  std::to_string(image.width) + " x " + std::to_string(image.height) +
                  " but the camera intrinsics are for " + std::to_string(camera.width) + " x " +
                  std::to_string(camera.height));
}

}  // namespace

bool PairSelectionOptions::Check(std::string* why) const {
  if (!(max_pair_offset_s > 0.0) || !(still_window_s >= 0.0)) {
    *why = "max_pair_offset_s must be > 0 and still_window_s >= 0";
    return false;
  }
  if (!(still_translation_m >= 0.0) || !(still_rotation_deg >= 0.0) ||
      !(duplicate_translation_m >= 0.0) || !(duplicate_rotation_deg >= 0.0)) {
    *why = "stillness and duplicate thresholds must be >= 0";
    return false;
  }
  if (!(ringless_integration_s >= 0.0 && ringless_integration_s <= 5.0)) {
    *why = "ringless_integration_s must be in [0, 5] s";
    return false;
  }
  if (!(retry_s > 0.0) || !(lidar_blind_s > 0.0)) {
    *why = "retry_s and lidar_blind_s must be > 0";
    return false;
  }
  if (board_sample_images < 1) {
    *why = "board_sample_images must be >= 1";
    return false;
  }
  if (!(moving_after_s >= 0.0) || !(moving_images_s > 0.0 && moving_images_s <= 5.0) ||
      moving_min_frames < 2 || !(moving_min_travel_m > 0.0) || !(moving_min_turn_deg > 0.0)) {
    *why =
        "moving_after_s must be >= 0, moving_images_s in (0, 5] s, moving_min_frames >= 2, "
        "moving_min_travel_m and moving_min_turn_deg > 0";
    return false;
  }
  return lidar_motion.Check(why) && limits.Check(why);
}

CameraVerdict JudgeCameraSide(const ImageU8& image, std::size_t others,
                              const std::function<std::optional<ImageU8>(std::size_t)>& other_image,
                              const CameraModel& camera, const BoardSpec& board,
                              const std::vector<Pose>& kept, const PairSelectionOptions& options) {
  CameraVerdict verdict;
  verdict.searched = true;
  std::string why;
  const std::optional<BoardDetection> detection =
      DetectBoard(image, board, BoardDetectionOptions{}, &why);
  if (!detection) {
    verdict.dropped = "board not found in the image";
    return verdict;
  }
  verdict.found = true;
  const auto observation = EstimateBoardPose(camera, *detection, PnpOptions{}, &why);
  if (!observation) {
    verdict.dropped = "board pose failed in the image";
    return verdict;
  }
  const Pose& pose = observation->cam_from_board;
  for (std::size_t i = 0; i < others; ++i) {
    const std::optional<ImageU8> other = other_image(i);
    if (!other) continue;
    verdict.stillness_checked = true;
    if (!StillIn(image, *detection, *other, camera, pose, options)) {
      verdict.dropped =
          "board moving (within " + MillisecondsText(options.still_window_s / 2) + ")";
      verdict.moving = true;
      return verdict;
    }
  }
  for (const Pose& kept_pose : kept)
    if (Within(BoardPoseError(kept_pose, pose, board), options.duplicate_translation_m,
               options.duplicate_rotation_deg)) {
      verdict.dropped = "near-duplicate board pose";
      return verdict;
    }
  verdict.cam_from_board = pose;
  return verdict;
}

ImageU8 DecodeTryMessageImage(const recording_detail::StampedBytes& image, const PairTopics& topics,
                              const LoadLimits& limits) {
  return topics.compressed_image ? DecodeCompressedImage(*image.bytes, topics.image, limits).image
                                 : DecodeImage(*image.bytes, topics.image, limits).image;
}

TryOutcome JudgeTry(const recording_detail::Try& attempt, std::optional<ImageU8> decoded,
                    const PairTopics& topics, const BoardSpec& board, const std::vector<Pose>& kept,
                    const PairSelectionOptions& options, const std::string& source) {
  TryOutcome outcome;
  ImageU8 image;
  try {
    image = decoded ? std::move(*decoded)
                    : DecodeTryMessageImage(attempt.image, topics, options.limits);
  } catch (const std::invalid_argument&) {
    outcome.dropped = "image unreadable";
    return outcome;
  }
  CheckImageSize(image, attempt.camera, topics, source);
  const CameraVerdict verdict = JudgeCameraSide(
      image, attempt.others.size(),
      [&](std::size_t i) -> std::optional<ImageU8> {
        try {
          return DecodeTryMessageImage(attempt.others[i], topics, options.limits);
        } catch (const std::invalid_argument&) {
          return std::nullopt;
        }
      },
      attempt.camera, board, kept, options);
  outcome.searched = verdict.searched;
  outcome.found = verdict.found;
  outcome.camera_moving = verdict.moving;
  if (!verdict.cam_from_board) {
    outcome.dropped = verdict.dropped;
    return outcome;
  }
  FoundPair pair;
  if (!DecodeTryCloud(attempt, topics, options.limits, &pair, &outcome.dropped)) return outcome;
  pair.cloud_stamp_ns = attempt.cloud.stamp_ns;
  pair.image_stamp_ns = attempt.image.stamp_ns;
  pair.image = std::move(image);
  pair.cam_from_board = *verdict.cam_from_board;
  pair.stillness_checked = verdict.stillness_checked;
  outcome.pair = std::move(pair);
  return outcome;
}

const FrameSearches::Search& FrameSearches::Of(const recording_detail::StampedBytes& frame,
                                               const PairTopics& topics, const CameraModel& camera,
                                               const BoardSpec& board, const LoadLimits& limits,
                                               const std::string& source, bool* searched_now) {
  *searched_now = false;
  if (const auto known = searches_.find(frame.stamp_ns); known != searches_.end())
    return known->second;
  Search& search = searches_[frame.stamp_ns];
  ImageU8 image;
  try {
    image = DecodeTryMessageImage(frame, topics, limits);
  } catch (const std::invalid_argument&) {
    return search;  // unreadable: no board there
  }
  CheckImageSize(image, camera, topics, source);
  *searched_now = true;
  std::string why;
  const auto detection = DetectBoard(image, board, BoardDetectionOptions{}, &why);
  if (!detection) return search;
  if (const auto observation = EstimateBoardPose(camera, *detection, PnpOptions{}, &why)) {
    search.cam_from_board = observation->cam_from_board;
    search.image = std::move(image);
  }
  return search;
}

ImageU8 FrameSearches::HandOut(std::int64_t stamp_ns) {
  const auto known = searches_.find(stamp_ns);
  if (known == searches_.end() || known->second.handed_out) return ImageU8{};
  known->second.handed_out = true;
  return known->second.image;
}

ImageU8 FrameSearches::Pixels(std::int64_t stamp_ns) const {
  const auto known = searches_.find(stamp_ns);
  return known == searches_.end() ? ImageU8{} : known->second.image;
}

void FrameSearches::Forget(std::int64_t oldest_ns) {
  searches_.erase(searches_.begin(), searches_.lower_bound(oldest_ns));
}

TryOutcome JudgeMovingTry(const recording_detail::Try& attempt, const PairTopics& topics,
                          const BoardSpec& board, const std::vector<Pose>& kept,
                          const PairSelectionOptions& options, const std::string& source,
                          FrameSearches* searches) {
  const std::int64_t stamp = attempt.cloud.stamp_ns;
  searches->Forget(stamp - recording_detail::Ns(2 * options.moving_images_s));
  std::vector<const recording_detail::StampedBytes*> frames{&attempt.image};
  for (const recording_detail::StampedBytes& other : attempt.others) frames.push_back(&other);
  std::sort(frames.begin(), frames.end(),
            [](const auto* a, const auto* b) { return a->stamp_ns < b->stamp_ns; });
  TryOutcome outcome;
  FoundPair pair;
  bool before = false, after = false;
  std::vector<Pose> poses;
  for (const recording_detail::StampedBytes* frame : frames) {
    bool searched_now = false;
    const FrameSearches::Search& search =
        searches->Of(*frame, topics, attempt.camera, board, options.limits, source, &searched_now);
    outcome.searched += searched_now;
    if (!search.cam_from_board) continue;
    outcome.found += searched_now;
    before |= frame->stamp_ns <= stamp;
    after |= frame->stamp_ns >= stamp;
    pair.frames.push_back({frame->stamp_ns, ImageU8{}});
    poses.push_back(*search.cam_from_board);
    if (pair.frames.size() == 1 ||
        std::llabs(frame->stamp_ns - stamp) < std::llabs(pair.image_stamp_ns - stamp)) {
      pair.image_stamp_ns = frame->stamp_ns;
      pair.cam_from_board = *search.cam_from_board;
    }
  }
  if (static_cast<int>(pair.frames.size()) < options.moving_min_frames || !before || !after) {
    outcome.dropped = "moving: the board not in " + std::to_string(options.moving_min_frames) +
                      " frames around the sweep, on both sides of it";
    return outcome;
  }
  // Still: the board travels less over the frames than any wave does (a wave at 0.3 m/s moves
  // it 13 cm over +-0.45 s; the floor leaves PnP's own jitter room); a checkerboard's two corner
  // orders are one pose.
  const bool still = std::all_of(poses.begin(), poses.end(), [&](const Pose& pose) {
    return Within(BoardPoseError(pose, pair.cam_from_board, board), options.moving_min_travel_m,
                  options.moving_min_turn_deg);
  });
  outcome.camera_still = still;
  if (still && attempt.ringless) {
    outcome.dropped =
        "moving: the camera saw the board still (a ring-less LiDAR's hold is tried blind, "
        "integrated)";
    return outcome;
  }
  if (still && std::any_of(kept.begin(), kept.end(), [&](const Pose& kept_pose) {
        return Within(BoardPoseError(kept_pose, pair.cam_from_board, board),
                      options.duplicate_translation_m, options.duplicate_rotation_deg);
      })) {
    outcome.dropped = "near-duplicate board pose";
    return outcome;
  }
  if (!DecodeTryCloud(attempt, topics, options.limits, &pair, &outcome.dropped)) return outcome;
  pair.cloud_stamp_ns = stamp;
  if (still) {  // a hold after all: its nearest frame, as a still pair's image
    pair.image = searches->Pixels(pair.image_stamp_ns);
    pair.frames.clear();
    outcome.pair = std::move(pair);
    return outcome;
  }
  for (FoundFrame& frame : pair.frames) frame.image = searches->HandOut(frame.stamp_ns);
  outcome.pair = std::move(pair);
  return outcome;
}

}  // namespace calibench
