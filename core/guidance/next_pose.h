// Where to hold the board next: the expected information of a board pose under the solver's own
// residual model (planes and board edges), whether the pose is feasible for both sensors, and the
// feasible pose that shrinks the uncertainty most in units of the user's goal.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/guidance/detection_reach.h"
#include "core/lidar/beam_table.h"
#include "core/lidar/board_returns.h"
#include "core/lidar/cloud.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench {

// What the user asks of the calibration: 1σ per axis (camera frame), translation and rotation.
struct CaptureGoal {
  double translation_mm = 5.0;
  double rotation_deg = 0.1;
  bool Check(std::string* why) const;
};

// What guidance knows of the two sensors, learnt from the data seen so far (LearnSensorGeometry)
// or, in the simulator, from its models.
struct SensorGeometry {
  CameraModel camera;
  BoardSpec board;
  BeamTable lidar;              // ring elevations and azimuth steps
  double min_distance_m = 1.0;  // board centre from the camera, the usable range
  double max_distance_m = 4.0;
  double range_sigma_m = 0.01;  // LiDAR range noise (1σ along the ray)
  // The beam's jitter across the ray (1σ per axis, radians), where the data resolve it
  // (core/target/lidar_noise.h): oblique and far boards are then noisier along their rays.
  double angular_sigma_rad = 0.0;
  double corner_sigma_px = 0.3;  // corner noise (1σ per coordinate)
  DetectionReach reach;          // the camera detector's reach measured on this rig, if any
  bool Check(std::string* why) const;
};

// The LiDAR's rings from its clouds: each ring's elevation (median over its returns) and the
// azimuth step (median gap between neighbouring returns of a ring). Only rings with at least 20
// returns count. Clouds without rings (a Livox-class scanner, a swept or nodding one) give their
// rays instead (LearntRayTable): those of the whole scan with the most returns, in its order, so
// that a board is predicted to return what that integration's rays would meet of it. Board
// segments alone give an empty table.
BeamTable LearnBeamTable(const std::vector<const LidarCloud*>& clouds);

// The rest of SensorGeometry from the pairs' features: the distance range of the boards seen so
// far (widened by 10 % and to at least 1 m of span, never below the nearest seen − 0.5 m), the
// LiDAR's noise (the median plane RMS as range noise; where the boards resolve an angular term,
// EstimateLidarNoise's range and angular σ instead) and the median PnP corner noise. Needs one
// accepted pair.
std::optional<SensorGeometry> LearnSensorGeometry(const CameraModel& camera, const BoardSpec& board,
                                                  const BeamTable& lidar,
                                                  const std::vector<PairFeatures>& pairs,
                                                  std::string* why);

struct GuidanceOptions {
  double image_margin_fraction = 0.03;  // the whole sheet this far inside the image (of width)
  double min_square_px = 12.0;          // a pattern square at least this wide in the image
  BoardReturnsRule lidar_returns;       // predicted returns on the sheet enough to find it
  double max_incidence_deg = 60.0;      // board normal against the ray, for both sensors
  // The candidate grid (camera frame): distances across the usable range, image cells, and
  // tilts of the board about its vertical and horizontal axes and in its own plane.
  int distance_steps = 4;
  int image_columns = 3;
  int image_rows = 3;
  std::vector<double> yaw_deg{-45, -25, 0, 25, 45};
  std::vector<double> pitch_deg{-40, -20, 0, 20, 40};
  std::vector<double> roll_deg{0, 45, -45};
  // Candidates this close to a board already held (camera frame) are not suggested again.
  double repeat_distance_m = 0.15;
  double repeat_angle_deg = 10.0;
  // While the camera's intrinsics are being estimated: the image cells that still lack corners
  // (EmptyCells, pixels), where the distortion must be seen. A candidate's score is multiplied
  // by 1 + intrinsics_cover_weight · (1 − its cells / the most cells any candidate covers) (with
  // a solution; without one, that is added): the best-covering keeps its score.
  std::vector<Eigen::AlignedBox2d> intrinsics_cells_to_cover;
  double intrinsics_cover_weight = 1.0;
  // The hand that holds the board misses the suggested pose by up to this much: uniform in
  // ±hand_tolerance_m per axis (camera frame) and a turn of up to hand_tolerance_deg about any
  // axis. A candidate is scored by its expected Σ (σ/goal)² over hand_samples such placements (a
  // placement the sensors cannot use adds nothing), so a pose at the edge of the detector's reach
  // loses to a robust one; the robust_candidates best by their nominal score are scored so.
  // A placement counts as usable within the pipeline's own reach, wider than the limits above
  // that suggestions keep to (a suggestion keeps a margin; a pose the hand moved a little beyond
  // it is not lost): these, tightened by the reach measured on the rig (SensorGeometry::reach).
  // Suggestions also keep this far inside the detector's reach (DetectableSquarePx and
  // SensorGeometry::reach): squares this much wider, angles this much smaller.
  double reach_square_margin = 1.25;
  double reach_angle_margin_deg = 5.0;
  double usable_max_incidence_deg = 75.0;
  bool keep_to_distance_range = true;  // SensorGeometry's distances (false: judged by reach only)
  double usable_min_square_px = 8.0;
  double usable_image_margin_fraction = 0.0;
  BoardReturnsRule usable_lidar_returns{3, 3, 20};
  double hand_tolerance_m = 0.10;
  double hand_tolerance_deg = 10.0;
  int hand_samples = 16;
  int robust_candidates = 40;
  // The tolerance told with a suggestion is the widest (of the hand's, halved in turn or place,
  // halved in both, quartered) within which this share of placements is usable.
  double tolerance_usable_share = 0.9;
  bool Check(std::string* why) const;
};

// The board's noise-free returns for a pose: the points and, per ring, where it leaves the sheet
// (the ray caster the simulator scans with, core/lidar/board_returns.h).
BoardReturns PredictBoardReturns(const SensorGeometry& sensors, const Pose& lidar_from_board);

struct Feasibility {
  bool feasible = false;
  std::string why;  // the first failed check, in words
  int rings = 0;    // rings with enough returns on the sheet; 0 for a ring-less LiDAR
  int points = 0;
  double camera_incidence_deg = 0.0;
  double lidar_incidence_deg = 0.0;
  double distance_m = 0.0;
};
// cam_from_board in BoardSpec's frame (z away from the camera); cam_from_lidar the current
// estimate. The LiDAR checks are skipped when cam_from_lidar is absent (no solution yet).
Feasibility CheckFeasible(const SensorGeometry& sensors, const std::optional<Pose>& cam_from_lidar,
                          const Pose& cam_from_board, const GuidanceOptions& options,
                          BoardReturns* returns = nullptr);

// One planned pair as the solver would see it: true planes with their Cramér–Rao covariances at
// the sensors' noise, and the board edges the rings would cross.
PlanePair PlannedPair(const SensorGeometry& sensors, const Pose& cam_from_lidar,
                      const Pose& cam_from_board, const BoardReturns& returns);

// How precisely a suggested pose must be held: placements within ±translation_m per axis and
// rotation_deg of turn are usable with probability usable_share (by the sampled hand model).
struct HoldTolerance {
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  double usable_share = 1.0;
  std::string words;  // "anywhere within a hand's width of it is fine (±10 cm, ±10°)"
};

struct PoseSuggestion {
  Pose cam_from_board = Pose::Identity();    // BoardSpec frame
  std::optional<Pose> lidar_from_board;      // shown frame (ShownFromBoardSpec); with a solution
  Vec3 predicted_sigma_t_mm = Vec3::Zero();  // after adding this pose (with a solution)
  Vec3 predicted_sigma_r_deg = Vec3::Zero();
  double score = 0.0;  // Σ (predicted σ / goal)² over the six axes (lower is better)
  // Of GuidanceOptions::intrinsics_cells_to_cover, the cells this pose puts corners in.
  int intrinsics_cells_covered = 0;
  Feasibility feasibility;
  // Of placements within the hand's error (GuidanceOptions::hand_tolerance_*), the share the
  // sensors can use; and the tolerance to tell the person.
  double usable_share = 1.0;
  HoldTolerance tolerance;
  std::string words;
};

// The feasible candidate that leaves the smallest Σ (σ/goal)² over the six axes after it is
// added (dominated by the weakest direction; ties by the largest ratio): Σ' = (Σ⁻¹ + I)⁻¹ with I
// its expected information at the current variance factors, discounted direction by direction
// by how much wider than the model the reported covariance is. Without a solution (fewer than 3
// pairs), the feasible pose that differs most from the boards seen so far (`seen`, camera frame),
// frontal first.
std::optional<PoseSuggestion> NextBestPose(const SensorGeometry& sensors,
                                           const std::optional<SolverResult>& solution,
                                           const std::vector<Pose>& seen, const CaptureGoal& goal,
                                           const GuidanceOptions& options,
                                           const SolverOptions& solver_options, std::string* why);

// The board frame shown to people (docs/architecture.md, "Conventions and file contracts"): origin
// at the sheet centre, x along its width, y up on the print, z out of the printed face: BoardSpec's
// frame turned 180° about x.
Pose ShownFromBoardSpec();

// "too oblique to the <sensor> (<angle> deg, at most <max>)": the one wording of that refusal.
std::string TooOblique(const char* sensor, double angle_deg, double max_deg);

// Words a person can follow while holding the board: distance, where in the image, how to turn
// it. E.g. "about 2.5 m away, left third of the image, turn it ~30° about its vertical axis (left
// edge nearer), keep it upright".
std::string DescribeBoardPose(const CameraModel& camera, const Pose& cam_from_board);

// A board held (cam_from_board, BoardSpec frame) against the pose suggested for it: it matches
// within the suggestion's tolerance (per axis of the centre, and between the normals; without
// one, options.repeat_distance_m of the centre and options.repeat_angle_deg). `words` say by how
// much, either way.
struct SuggestionMatch {
  bool matches = false;
  double offset_m = 0.0;
  double angle_deg = 0.0;
  std::string words;
};
// Placements a hand gives for `target`: hand_samples draws (fixed, so advice is repeatable and
// candidates are compared on the same draws), scaled to the tolerance given.
std::vector<Pose> HandPlacements(const Pose& target, double translation_m, double rotation_deg,
                                 int samples);

SuggestionMatch MatchSuggestion(const Pose& cam_from_board, const PoseSuggestion& suggestion,
                                const GuidanceOptions& options);

}  // namespace calibench
