// Camera-guided completion of the LiDAR boards (pipeline.h, CompleteWithCamera): the solution
// predicts where each pair's board lies in the LiDAR frame; boards that disagree are not used,
// and the board is looked for again at the prediction.
#include <cmath>
#include <cstdio>

#include "core/base/parallel.h"
#include "core/io/cloud_io.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {
namespace {

// The camera's board in the LiDAR frame: its plane (normal towards the LiDAR) and centre.
struct PredictedBoard {
  Plane plane;
  Vec3 centre = Vec3::Zero();
  Mat3 normal_covariance = Mat3::Zero();  // the camera's normal's, in the LiDAR frame
};

PredictedBoard Predict(const CameraBoardObservation& camera, const Pose& cam_from_lidar) {
  // x_c = R x_l + t, so n_c·x_c + d_c = (Rᵀ n_c)·x_l + (n_c·t + d_c).
  const Mat3 rotation = cam_from_lidar.linear();
  const Vec3 t = cam_from_lidar.translation();
  PredictedBoard board;
  board.plane.normal = rotation.transpose() * camera.plane.normal;
  board.plane.distance = camera.plane.distance + camera.plane.normal.dot(t);
  if (board.plane.distance < 0) {
    board.plane.normal = -board.plane.normal;
    board.plane.distance = -board.plane.distance;
  }
  board.centre = cam_from_lidar.inverse() * camera.cam_from_board.translation();
  board.normal_covariance =
      rotation.transpose() * camera.plane_covariance.topLeftCorner<3, 3>() * rotation;
  return board;
}

// Why the LiDAR board disagrees with the prediction, or "" when it agrees. The tilt is judged in
// the direction it disagrees: both normals' covariances there (the LiDAR's with its rings'
// range biases, LidarPlaneFit::ring_bias_covariance), so a strip that few rings cross may tilt
// more about the rings' direction than a full board, and no more about the other axis. The
// offset likewise; the options' floors add in quadrature.
std::string Disagreement(const LidarPlaneFit& lidar, const CameraBoardObservation& camera,
                         const PredictedBoard& predicted, double sheet_diagonal_m,
                         const PipelineOptions& options) {
  const Vec3& lidar_centre = lidar.inlier_centroid;
  const double cosine = lidar.plane.normal.dot(predicted.plane.normal);
  const double angle = std::acos(std::min(1.0, std::abs(cosine)));
  const double offset = std::abs(predicted.plane.SignedDistance(lidar_centre));
  const double shift = (lidar_centre - predicted.centre).norm();
  const Mat4 lidar_covariance = lidar.covariance + lidar.ring_bias_covariance;
  const Mat3 normal_covariance =
      lidar_covariance.topLeftCorner<3, 3>() + predicted.normal_covariance;
  // The direction in which the normals differ (perpendicular to the predicted normal); with none
  // (they agree exactly) any direction does.
  Vec3 direction = (cosine < 0 ? -lidar.plane.normal : lidar.plane.normal) - predicted.plane.normal;
  direction -= direction.dot(predicted.plane.normal) * predicted.plane.normal;
  const double model_angle_variance =
      direction.norm() > 1e-12
          ? std::max(0.0, direction.normalized().dot(normal_covariance * direction.normalized()))
          : normal_covariance.trace();
  const double floor_angle = options.guided_floor_sigma_deg * kDegToRad;
  const double sigma_angle = std::sqrt(model_angle_variance + floor_angle * floor_angle);
  const double sigma_offset =
      std::sqrt(lidar_covariance(3, 3) + camera.plane_covariance(3, 3) +
                options.guided_floor_sigma_m * options.guided_floor_sigma_m);
  const double max_angle = options.guided_max_sigmas * sigma_angle;
  const double max_offset = options.guided_max_sigmas * sigma_offset;
  if (angle <= max_angle && offset <= max_offset && shift <= 0.5 * sheet_diagonal_m) return "";
  char text[240];
  std::snprintf(text, sizeof(text),
                "LiDAR board disagrees with the camera's by %.1f deg, %.0f mm off its plane, "
                "%.0f mm from its centre (allowed %.1f deg in that direction, %.0f mm; "
                "%.0f mm from the centre)",
                angle * kRadToDeg, offset * 1e3, shift * 1e3, max_angle * kRadToDeg,
                max_offset * 1e3, 0.5 * sheet_diagonal_m * 1e3);
  return text;
}

struct Review {
  bool changed = false;
  std::optional<LidarPlaneFit> lidar;
  BoardOrigin origin;
  std::string failure;  // non-empty: the pair fails with it
};

// One pair against the prediction: keep an agreeing board, else look at the prediction.
Review ReviewPair(const Dataset& dataset, const PairEntry& entry, const PairFeatures& pair,
                  const Pose& cam_from_lidar, const PipelineOptions& options) {
  Review review;
  const PredictedBoard predicted = Predict(*pair.camera, cam_from_lidar);
  const double diagonal = std::hypot(dataset.target.SheetWidth(), dataset.target.SheetHeight());
  // A seed is the user's word: its board is checked, never replaced.
  if (!pair.lidar && pair.board_origin.source == BoardSource::kSeed) return review;
  std::string disagreement;
  if (pair.lidar) {
    disagreement = Disagreement(*pair.lidar, *pair.camera, predicted, diagonal, options);
    if (disagreement.empty()) return review;               // agrees: unchanged
    if (pair.board_origin.source == BoardSource::kSeed) {  // the user's seed wins: flag only
      review.changed = pair.status == PairStatus::kAccepted;
      review.lidar = pair.lidar;
      review.origin = pair.board_origin;
      review.failure = disagreement;
      return review;
    }
  }
  // Only now is the cloud needed: to look for the board where the camera says it is.
  LidarCloud cloud;
  try {
    cloud = LoadCloud(entry.cloud);
  } catch (const IoError&) {
    return review;  // the pair already failed on its input
  }
  // The sheet's inscribed disc about the predicted centre, and only the returns near the
  // predicted plane: the whole board's returns where a sparse scanner leaves a few strokes of
  // them (a Livox frame), without the wall behind.
  BoardHint hint;
  hint.seed = LidarSeed{predicted.centre,
                        0.5 * std::min(dataset.target.SheetWidth(), dataset.target.SheetHeight())};
  hint.seed_from_camera = true;
  hint.predicted_plane = predicted.plane;
  std::string why;
  BoardOrigin origin;
  auto fit = ExtractLidarFeatures(dataset, cloud, hint, options, &why, &origin);
  if (fit) {
    const std::string again = Disagreement(*fit, *pair.camera, predicted, diagonal, options);
    if (again.empty()) {
      origin.detail = pair.board_origin.source == BoardSource::kDetected && pair.lidar
                          ? "at the camera's prediction; detection had found " +
                                pair.board_origin.detail + " (" + disagreement + ")"
                          : "at the camera's prediction";
      review.changed = true;
      review.lidar = std::move(fit);
      review.origin = origin;
      return review;
    }
    why = again;
  }
  // Nothing agreeing at the prediction either: the pair fails with the first reason.
  review.changed = pair.status == PairStatus::kAccepted;
  review.failure = disagreement.empty() ? why : disagreement;
  review.origin = pair.board_origin;
  return review;
}

}  // namespace

void CompleteWithCamera(const Dataset& dataset, const std::vector<const PairEntry*>& pairs,
                        const PipelineOptions& options, const PairEdits& edits,
                        CalibrationOutcome* outcome) {
  CALIBENCH_CHECK(pairs.size() == outcome->pairs.size());
  for (int round = 0; round < 3 && outcome->solution; ++round) {
    const Pose cam_from_lidar = outcome->solution->cam_from_lidar;
    std::vector<Review> reviews(pairs.size());
    ParallelFor(pairs.size(), options.threads, [&](size_t i) {
      const PairFeatures& pair = outcome->pairs[i];
      const auto edit = edits.find(pair.id);
      const bool brushed = edit != edits.end() && edit->second.brush_pixels;
      if (pair.input_error || !pair.camera || brushed || pair.status == PairStatus::kRejected)
        return;
      reviews[i] = ReviewPair(dataset, *pairs[i], pair, cam_from_lidar, options);
    });
    bool changed = false;
    std::vector<PairFeatures> features = outcome->pairs;
    for (size_t i = 0; i < pairs.size(); ++i) {
      Review& review = reviews[i];
      if (!review.changed && review.failure.empty()) continue;
      PairFeatures& pair = features[i];
      const PairStatus before = pair.status;
      pair.lidar = std::move(review.lidar);
      pair.board_origin = review.origin;
      SetStatusFromFeatures(&pair, review.failure, "");
      if (!review.failure.empty()) {
        pair.status = PairStatus::kFailed;
        pair.reason = review.failure;
        pair.lidar.reset();
      }
      changed = changed || review.changed || pair.status != before;
    }
    if (!changed) return;
    const std::string background_note = outcome->background_note;
    CalibrationOutcome next = SolveFromFeatures(std::move(features), options);
    if (!next.solution) return;  // keep the last solution rather than none
    *outcome = std::move(next);
    outcome->background_note = background_note;
  }
}

std::string BoardDisagreement(const LidarPlaneFit& lidar, const CameraBoardObservation& camera,
                              const Pose& cam_from_lidar, const BoardSpec& target,
                              const PipelineOptions& options) {
  return Disagreement(lidar, camera, Predict(camera, cam_from_lidar),
                      std::hypot(target.SheetWidth(), target.SheetHeight()), options);
}

}  // namespace calibench
