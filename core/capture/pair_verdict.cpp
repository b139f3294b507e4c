#include "core/capture/pair_verdict.h"

#include <cmath>

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
  if (attempt.camera.width != image.width || attempt.camera.height != image.height)
    throw IoError(source + ": the images on " + topics.image_topic + " are " +
                  std::to_string(image.width) + " x " + std::to_string(image.height) +
                  " but the camera intrinsics are for " + std::to_string(attempt.camera.width) +
                  " x " + std::to_string(attempt.camera.height));
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
  if (!verdict.cam_from_board) {
    outcome.dropped = verdict.dropped;
    return outcome;
  }
  FoundPair pair;
  try {
    CloudMessage message =
        DecodeCloudMessage(*attempt.cloud.bytes, topics.livox_cloud, topics.cloud, options.limits);
    pair.cloud = std::move(message.cloud);
    pair.point_times = std::move(message.point_times);
    IntegrateSweeps(attempt.integrated, topics, options.limits, attempt.cloud.stamp_ns,
                    &pair.cloud);
  } catch (const std::invalid_argument&) {
    outcome.dropped = "cloud message unreadable";
    return outcome;
  }
  if (pair.cloud.size() == 0) {
    outcome.dropped = "cloud has no finite point";
    return outcome;
  }
  pair.cloud_stamp_ns = attempt.cloud.stamp_ns;
  pair.image_stamp_ns = attempt.image.stamp_ns;
  pair.image = std::move(image);
  pair.cam_from_board = *verdict.cam_from_board;
  pair.stillness_checked = verdict.stillness_checked;
  outcome.pair = std::move(pair);
  return outcome;
}

}  // namespace calibench
