#include "core/guidance/preflight.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

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

std::vector<PreflightFinding> PreflightPair(const PreflightInputs& in,
                                            const PreflightOptions& options) {
  std::vector<PreflightFinding> findings;
  char text[300];
  auto add = [&](const char* check, PreflightSeverity severity) {
    findings.push_back({check, severity, text});
  };
  const PairFeatures& pair = *in.pair;
  const CameraBoardObservation* camera = pair.camera ? &*pair.camera : nullptr;
  const LidarPlaneFit* lidar = pair.lidar ? &*pair.lidar : nullptr;
  // The sheet's outline against the image border.
  if (camera && in.camera && in.board) {
    const double hw = 0.5 * in.board->SheetWidth(), hh = 0.5 * in.board->SheetHeight();
    const Vec3 corners[4] = {{-hw, -hh, 0}, {hw, -hh, 0}, {hw, hh, 0}, {-hw, hh, 0}};
    int outside = 0, samples = 0;
    for (int e = 0; e < 4; ++e) {
      for (int k = 0; k < 8; ++k, ++samples) {
        const Vec3 p =
            camera->cam_from_board * (corners[e] + (corners[(e + 1) % 4] - corners[e]) * (k / 8.0));
        const auto pixel = p.z() > 0 ? in.camera->Project(p) : std::nullopt;
        outside += !pixel || !in.camera->InImage(*pixel, options.border_margin_px);
      }
    }
    if (outside > 0) {
      std::snprintf(text, sizeof(text),
                    "the board is cut by the image border (%d of %d points of its outline "
                    "outside): its edges cannot be checked there",
                    outside, samples);
      add("image-border", PreflightSeverity::kWeak);
    }
  }
  // Rings on the sheet.
  if (lidar && lidar->num_rings > 0) {
    if (lidar->num_rings < options.min_rings) {
      std::snprintf(text, sizeof(text),
                    "only %d LiDAR ring%s on the sheet (at least %d): the plane's tilt across the "
                    "rings is not determined",
                    lidar->num_rings, lidar->num_rings == 1 ? "" : "s", options.min_rings);
      add("rings", PreflightSeverity::kReject);
    }
  }
  // Incidence for both sensors.
  auto incidence = [](const Plane& plane, const Vec3& point) {
    return std::acos(std::min(1.0, std::abs(plane.normal.dot(point.normalized())))) * kRadToDeg;
  };
  if (camera) {
    const double angle = incidence(camera->plane, camera->cam_from_board.translation());
    if (angle > options.max_incidence_deg) {
      std::snprintf(text, sizeof(text), "too oblique to the camera (%.0f deg, at most %.0f)", angle,
                    options.max_incidence_deg);
      add("oblique", PreflightSeverity::kReject);
    }
  }
  if (lidar) {
    const double angle = incidence(lidar->plane, lidar->inlier_centroid);
    if (angle > options.max_incidence_deg) {
      std::snprintf(text, sizeof(text), "too oblique to the LiDAR (%.0f deg, at most %.0f)", angle,
                    options.max_incidence_deg);
      add("oblique", PreflightSeverity::kReject);
    }
  }
  // Motion blur.
  if (pair.edge_width_px) {
    if (const double width = *pair.edge_width_px; width > options.max_edge_width_px) {
      std::snprintf(text, sizeof(text),
                    "motion blur: the squares' edges are %.1f px wide (a still board: under "
                    "%.1f px); hold it still",
                    width, options.max_edge_width_px);
      add("blur", PreflightSeverity::kReject);
    }
  }
  // Stamps (recordings).
  if (in.stamp_offset_s && std::abs(*in.stamp_offset_s) > options.max_stamp_offset_s) {
    std::snprintf(text, sizeof(text),
                  "cloud and image are %.0f ms apart (at most %.0f ms): the board may have moved "
                  "between them",
                  std::abs(*in.stamp_offset_s) * 1e3, options.max_stamp_offset_s * 1e3);
    add("stamps", PreflightSeverity::kReject);
  }
  // The board moved between the two sensors: disagrees with the solution's prediction.
  if (lidar && camera && in.cam_from_lidar && in.board && in.pipeline) {
    const std::string disagreement =
        BoardDisagreement(*lidar, *camera, *in.cam_from_lidar, *in.board, *in.pipeline);
    if (!disagreement.empty()) {
      std::snprintf(text, sizeof(text),
                    "the board moved between the two sensors, or one of them saw something "
                    "else: %s",
                    disagreement.c_str());
      add("moved", PreflightSeverity::kReject);
    }
  }
  // A near duplicate of an earlier pose adds almost nothing.
  if (camera && in.earlier) {
    for (const PairFeatures& other : *in.earlier) {
      if (!other.camera || other.status != PairStatus::kAccepted) continue;
      const double distance =
          (other.camera->cam_from_board.translation() - camera->cam_from_board.translation())
              .norm();
      const double angle =
          RotationAngle(other.camera->cam_from_board.linear(), camera->cam_from_board.linear()) *
          kRadToDeg;
      if (distance <= options.duplicate_translation_m && angle <= options.duplicate_angle_deg) {
        std::snprintf(text, sizeof(text),
                      "this pose adds almost nothing: the board is within %.0f mm and %.1f deg of "
                      "pair %s; move it elsewhere",
                      distance * 1e3, angle, other.id.c_str());
        add("duplicate", PreflightSeverity::kWeak);
        break;
      }
    }
  }
  return findings;
}

}  // namespace calibench
