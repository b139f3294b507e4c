// Pre-flight checks of one pair, in words: what makes a pair useless (rejected) or worth little
// (weak) before it is trusted to the solve.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"

namespace calibench {

struct PreflightOptions {
  double border_margin_px = 2.0;    // the sheet's outline this far inside the image
  int min_rings = 3;                // rings with returns on the sheet
  double max_incidence_deg = 60.0;  // board normal against either sensor's ray
  // Motion blur: OpenCV's chessboard sharpness (the mean width of the squares' edges, pixels).
  // A sharp print measures 1.5-2.5 px; a board moved during the exposure smears wider.
  double max_edge_width_px = 4.0;
  double max_stamp_offset_s = 0.05;  // cloud against image (recordings)
  // Near duplicates: a board within this much of an earlier one (camera frame).
  double duplicate_translation_m = 0.05;
  double duplicate_angle_deg = 3.0;
  bool Check(std::string* why) const;
};

enum class PreflightSeverity { kWeak, kReject };

struct PreflightFinding {
  // "image-border", "rings", "oblique", "blur", "stamps", "moved", "duplicate"; and from advise,
  // "reach": why the camera missed a board the LiDAR placed (LearnDetectionReach).
  std::string check;
  PreflightSeverity severity = PreflightSeverity::kWeak;
  std::string words;
};

struct PreflightInputs {
  const PairFeatures* pair = nullptr;  // its features (lidar fit, camera pose)
  const CameraModel* camera = nullptr;
  const BoardSpec* board = nullptr;
  std::optional<double> stamp_offset_s;                // recordings: cloud − image stamp
  std::optional<Pose> cam_from_lidar;                  // a solution without this pair, if any
  const std::vector<PairFeatures>* earlier = nullptr;  // pairs before it (duplicates)
  const PipelineOptions* pipeline = nullptr;           // the agreement gate's tolerances
};

// Every check that applies to what is given; empty when the pair is fine.
std::vector<PreflightFinding> PreflightPair(const PreflightInputs& inputs,
                                            const PreflightOptions& options);

}  // namespace calibench
