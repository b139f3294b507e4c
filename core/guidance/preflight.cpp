#include "core/guidance/preflight.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "core/guidance/next_pose.h"

namespace calibench {

bool PreflightOptions::Check(std::string* why) const {
  if (!(border_margin_px >= 0)) return *why = "border_margin_px must be >= 0", false;
  if (min_rings < 1) return *why = "min_rings must be >= 1", false;
  if (!(max_incidence_deg > 0 && max_incidence_deg < 90))
    return *why = "max_incidence_deg must be in (0, 90)", false;
  if (!(max_edge_width_px > 0)) return *why = "max_edge_width_px must be > 0", false;
  if (!(max_stamp_offset_s > 0)) return *why = "max_stamp_offset_s must be > 0", false;
  if (!(duplicate_translation_m >= 0 && duplicate_angle_deg >= 0))
    return *why = "the duplicate thresholds must be >= 0", false;
  return true;
}

namespace {

using Finding = std::optional<PreflightFinding>;

PreflightFinding Say(const char* check, PreflightSeverity severity, const char* format, ...)
    __attribute__((format(printf, 3, 4)));
PreflightFinding Say(const char* check, PreflightSeverity severity, const char* format, ...) {
  char text[300];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof(text), format, args);
  va_end(args);
  return {check, severity, text};
}

// The sheet's outline against the image border.
Finding ImageBorder(const CameraBoardObservation& camera, const CameraModel& model,
                    const BoardSpec& board, const PreflightOptions& options) {
  const double hw = 0.5 * board.SheetWidth(), hh = 0.5 * board.SheetHeight();
  const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
  int outside = 0, samples = 0;
  for (int e = 0; e < 4; ++e) {
    for (int k = 0; k < 8; ++k, ++samples) {
      const Vec3 p =
          camera.cam_from_board * (corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 8.0));
      const auto pixel = p.z() > 0 ? model.Project(p) : std::nullopt;
      outside += !pixel || !model.InImage(*pixel, options.border_margin_px);
    }
  }
  if (outside == 0) return std::nullopt;
  return Say("image-border", PreflightSeverity::kWeak,
             "the board is cut by the image border (%d of %d points of its outline outside): its "
             "edges cannot be checked there",
             outside, samples);
}

Finding Rings(const LidarPlaneFit& lidar, const PreflightOptions& options) {
  if (lidar.num_rings == 0 || lidar.num_rings >= options.min_rings) return std::nullopt;
  return Say("rings", PreflightSeverity::kReject,
             "only %d LiDAR ring%s on the sheet (at least %d): the plane's tilt across the rings "
             "is not determined",
             lidar.num_rings, lidar.num_rings == 1 ? "" : "s", options.min_rings);
}

// A plane seen from its sensor's origin at more than the allowed incidence.
Finding Oblique(const char* sensor, const Plane& plane, const Vec3& point,
                const PreflightOptions& options) {
  const double angle =
      std::acos(std::min(1.0, std::abs(plane.normal.dot(point.normalized())))) * kRadToDeg;
  if (angle <= options.max_incidence_deg) return std::nullopt;
  return PreflightFinding{"oblique", PreflightSeverity::kReject,
                          TooOblique(sensor, angle, options.max_incidence_deg)};
}

// A pair of a moving capture: its board seen in several frames (a wave), not held.
bool Waved(const PairFeatures& pair) { return pair.camera_track.size() >= 2; }

Finding Blur(const PairFeatures& pair, const PreflightOptions& options) {
  if (!pair.edge_width_px || *pair.edge_width_px <= options.max_edge_width_px) return std::nullopt;
  return Say("blur", PreflightSeverity::kReject,
             "motion blur: the squares' edges are %.1f px wide (a still board: under %.1f px); %s",
             *pair.edge_width_px, options.max_edge_width_px,
             Waved(pair) ? "wave it slower, or shorten the camera's exposure" : "hold it still");
}

Finding Stamps(std::optional<double> offset_s, const PreflightOptions& options) {
  if (!offset_s || std::abs(*offset_s) <= options.max_stamp_offset_s) return std::nullopt;
  return Say("stamps", PreflightSeverity::kReject,
             "cloud and image are %.0f ms apart (at most %.0f ms): the board may have moved "
             "between them",
             std::abs(*offset_s) * 1e3, options.max_stamp_offset_s * 1e3);
}

// The board moved between the two sensors: it disagrees with the solution's prediction.
Finding Moved(const LidarPlaneFit& lidar, const CameraBoardObservation& camera,
              const PreflightInputs& in) {
  const std::string disagreement =
      BoardDisagreement(lidar, camera, *in.cam_from_lidar, *in.board, *in.pipeline);
  if (disagreement.empty()) return std::nullopt;
  return Say("moved", PreflightSeverity::kReject,
             "the board moved between the two sensors, or one of them saw something else: %s",
             disagreement.c_str());
}

// A near duplicate of an earlier pose adds almost nothing. Not among a wave's sweeps: each comes
// a sweep after the last, near it by design, and each tells the clocks' offset (a board at 0.5
// m/s moves 5 cm a sweep); a wave passing a held pose again is a duplicate of the hold as ever.
Finding Duplicate(const PairFeatures& pair, const std::vector<PairFeatures>& earlier,
                  const PreflightOptions& options) {
  const CameraBoardObservation& camera = *pair.camera;
  for (const PairFeatures& other : earlier) {
    if (!other.camera || other.status != PairStatus::kAccepted) continue;
    if (Waved(pair) && Waved(other)) continue;
    const Pose& there = other.camera->cam_from_board;
    const double distance = (there.translation() - camera.cam_from_board.translation()).norm();
    const double angle = RotationAngle(there.linear(), camera.cam_from_board.linear()) * kRadToDeg;
    if (distance <= options.duplicate_translation_m && angle <= options.duplicate_angle_deg)
      return Say("duplicate", PreflightSeverity::kWeak,
                 "this pose adds almost nothing: the board is within %.0f mm and %.1f deg of "
                 "pair %s; move it elsewhere",
                 distance * 1e3, angle, other.id.c_str());
  }
  return std::nullopt;
}

}  // namespace

std::vector<PreflightFinding> PreflightPair(const PreflightInputs& in,
                                            const PreflightOptions& options) {
  const PairFeatures& pair = *in.pair;
  const CameraBoardObservation* camera = pair.camera ? &*pair.camera : nullptr;
  const LidarPlaneFit* lidar = pair.lidar ? &*pair.lidar : nullptr;
  std::vector<Finding> found;
  if (camera && in.camera && in.board)
    found.push_back(ImageBorder(*camera, *in.camera, *in.board, options));
  if (lidar) found.push_back(Rings(*lidar, options));
  if (camera)
    found.push_back(
        Oblique("camera", camera->plane, camera->cam_from_board.translation(), options));
  if (lidar) found.push_back(Oblique("LiDAR", lidar->plane, lidar->inlier_centroid, options));
  found.push_back(Blur(pair, options));
  found.push_back(Stamps(in.stamp_offset_s, options));
  if (lidar && camera && in.cam_from_lidar && in.board && in.pipeline)
    found.push_back(Moved(*lidar, *camera, in));
  if (camera && in.earlier) found.push_back(Duplicate(pair, *in.earlier, options));
  std::vector<PreflightFinding> findings;
  for (Finding& f : found)
    if (f) findings.push_back(std::move(*f));
  return findings;
}

}  // namespace calibench
