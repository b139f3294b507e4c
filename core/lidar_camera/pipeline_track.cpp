// A moving capture's camera side (core/lidar_camera/pipeline.h): the board posed in each frame
// of a pair, once per frame however many pairs list it (FrameBoards), in one corner order.
#include <algorithm>
#include <cmath>
#include <mutex>

#include "core/io/image_io.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {

std::optional<CameraBoardObservation> FrameBoards::Of(const Dataset& dataset,
                                                      const std::filesystem::path& image,
                                                      const PipelineOptions& options) {
  return Features(dataset, image, options, nullptr).observation;
}

CameraFeatures FrameBoards::Features(const Dataset& dataset, const std::filesystem::path& image,
                                     const PipelineOptions& options, const ImageU8* decoded) {
  {
    std::lock_guard lock(mutex_);
    if (const auto seen = seen_.find(image); seen != seen_.end()) return seen->second;
  }
  // Posed outside the lock: two workers asking for one frame at once both pose it, alike.
  CameraFeatures features;
  try {
    const ImageU8 frame = decoded ? ImageU8{} : LoadImage(image);
    const ImageU8& pixels = decoded ? *decoded : frame;
    if (pixels.width == dataset.camera.width && pixels.height == dataset.camera.height)
      features = ExtractCameraFeatures(dataset, pixels, options);
    else
      features.failure = image.string() + ": not the camera's size";
  } catch (const IoError& error) {
    features.failure = error.what();
  }
  std::lock_guard lock(mutex_);
  return seen_.emplace(image, std::move(features)).first->second;
}

void TurnCheckerboardObservation(const BoardSpec& board, CameraBoardObservation* observation) {
  const Mat3 half_turn = Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  observation->cam_from_board.linear() = observation->cam_from_board.rotation() * half_turn;
  Vec6 flip;
  flip << -1, -1, 1, -1, -1, 1;
  observation->pose_covariance =
      flip.asDiagonal() * observation->pose_covariance * flip.asDiagonal();
  BoardDetection& corners = observation->corners;
  for (Vec3& point : corners.board_points) point = half_turn * point;
  const int count = board.cols * board.rows;
  for (int& id : corners.ids) id = count - 1 - id;
}

std::vector<TimedObservation> TrackBoard(const Dataset& dataset, const PairEntry& pair,
                                         const PipelineOptions& options, FrameBoards* frames) {
  FrameBoards own;
  std::vector<TimedObservation> track;
  for (const StampedImage& frame : pair.images)
    if (auto board = (frames ? frames : &own)->Of(dataset, frame.image, options))
      track.push_back(
          {(frame.stamp_ns - pair.lidar_stamp_ns.value_or(0)) * 1e-9, std::move(*board)});
  std::sort(track.begin(), track.end(), [](const TimedObservation& a, const TimedObservation& b) {
    return a.stamp_s < b.stamp_s;
  });
  // A checkerboard's corners come back in either of two orders, 180 degrees apart about its
  // normal, frame by frame: each frame is taken in the turn nearest the previous frame's, or the
  // spline between two frames would swing through 90 degrees (the plane is the same either way).
  if (dataset.target.type == BoardType::kCheckerboard)
    for (std::size_t k = 1; k < track.size(); ++k) {
      const Mat3 previous = track[k - 1].observation.cam_from_board.rotation();
      const Mat3 now = track[k].observation.cam_from_board.rotation();
      const Mat3 turned = now * Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
      if (Eigen::AngleAxisd(previous.transpose() * turned).angle() <
          Eigen::AngleAxisd(previous.transpose() * now).angle())
        TurnCheckerboardObservation(dataset.target, &track[k].observation);
    }
  return track;
}

}  // namespace calibench
