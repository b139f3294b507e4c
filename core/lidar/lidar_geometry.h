// What kind of range sensor a cloud comes from, judged from the cloud alone, and so which noise
// model its planes get: a spinning LiDAR's returns lie on cones about one centre (its rings), so
// their noise lies along rays from the origin; a non-repetitive scanner (Livox-class: one beam
// steered by prisms) fires from one centre too but follows no rings; a swept single-line laser's
// rays start on a mirror that moves with the stage; a board-only segment holds too little to
// tell. Spinning and non-repetitive clouds are fitted on the ranges along their rays (only rings
// add ring biases; board edges come from rings' ends or the beam's path across the sheet's
// border, core/target/board_edges.h); a swept cloud is fitted along its rays where they are known
// (the cloud's viewpoints, or its mirror estimated: core/lidar/swept_origin.h), a segment and a
// swept cloud whose rays are not known get an isotropic point-to-plane model (the plane's own
// covariance).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/lidar/cloud.h"

namespace calibench {

enum class LidarGeometry { kSpinning, kSwept, kNonRepetitive, kSegment };
// "spinning", "swept", "non-repetitive", "segment"
std::string LidarGeometryName(LidarGeometry geometry);
std::optional<LidarGeometry> ParseLidarGeometry(const std::string& name);
std::string LidarGeometryNames();  // "spinning, swept, non-repetitive, segment", for messages

// Whether the geometry's rays start at the cloud's origin (their ranges measured along them):
// spinning and non-repetitive scanners.
bool RaysFromOrigin(LidarGeometry geometry);

// A cloud whose returns lie within this distance of their centre (metres, 90th percentile) is a
// segment: the board cropped out of a scan, with no scene around it. Whatever its field of view,
// a whole scan holds a room's walls and floor metres apart (a Livox Mid-40's 38° or a swept
// scan's 28° as much as a spinning LiDAR's 360°).
inline constexpr double kSegmentExtentM = 1.5;

struct LidarGeometryOptions {
  double max_segment_extent_m = kSegmentExtentM;  // within it a ring-less cloud is a segment
  // Rings from elevations: sorted returns split where consecutive elevations differ by more than
  // this; the clusters are cones about one centre when each is narrower than
  // max_ring_width_fraction of the median spacing between them (a spinning LiDAR without a ring
  // field). A mirror off the axis smears each beam's elevation with the range: no cones.
  double ring_gap_deg = 0.15;
  double max_ring_width_fraction = 0.25;
  int min_rings = 4;
  // Cones whose elevation moves with the range as from rays starting more than this far off the
  // origin (metres, 90th percentile over the cones) are a swept scanner's (its mirror off the
  // stage's axis), not a spinning LiDAR's. The statistic reads low (a band's extent over its
  // span of 1/r, where bands mix ranges and short spans): on the simulator central sensors read
  // 0.0 cm and a scanner whose mirror sits 10 cm in front of and 5 cm above the stage's axis
  // reads 1.5 cm. A real spinning LiDAR without a ring field whose lasers sit off its centre may
  // read above this: the summary says which model was chosen, --lidar-model overrides.
  double max_ray_offset_m = 0.01;
  bool Check(std::string* why) const;
};

struct LidarGeometryVerdict {
  LidarGeometry geometry = LidarGeometry::kSpinning;
  std::string why;      // what in the cloud decided it, in words
  bool forced = false;  // chosen by the user (--lidar-model), not from the cloud
};

// The model chosen by the data (core/lidar_camera/lidar_model_evidence.h): its options and what it
// found.
struct LidarModelEvidenceOptions {
  bool enabled = true;  // ring-less clouds' pairs fitted under both models and cross-validated
  int folds = 5;        // cross-validation folds over the usable pairs (at most one per pair)
  // Fewer usable pairs with both fits than this: the classifier's model stands (said so).
  int min_pairs = 6;
  // The models are told apart when the held-out pairs' log-ratio of their errors is this many
  // standard errors from 0 (a paired z) and their geometric mean ratio is at least tie_ratio;
  // otherwise the data cannot tell them apart: the look's model stands, and the summary says so.
  double min_significance_z = 2.0;
  double tie_ratio = 1.05;
  bool Check(std::string* why) const;
};

struct LidarModelCandidate {
  LidarGeometry geometry = LidarGeometry::kSegment;  // as the pairs' fits name it
  bool along_rays =
      false;  // ranges along rays (from an origin given or estimated), or point-to-plane
  // The median over held-out pairs of their board corners' RMS distance to the LiDAR plane moved
  // into the camera by the solve without them (metres); +inf when a fold could not be solved.
  double heldout_rms_m = 0.0;
  int heldout_pairs = 0;
};

struct LidarModelEvidence {
  // The criterion in words, as the result file's lidar_model.evidence.criterion.
  std::string criterion;
  std::vector<LidarModelCandidate> candidates;  // the winner first
  // The loser's held-out error over the winner's, the geometric mean over the held-out pairs
  // (>= 1), and how many standard errors its log is from 0.
  double margin = 1.0;
  double significance_z = 0.0;
  bool tie = false;  // below min_significance_z or tie_ratio: the data could not tell them apart
  LidarGeometry chosen = LidarGeometry::kSegment;
  int switched_pairs = 0;  // pairs holding the held-out pairs' choice against their cloud's look
  // The summary's sentence ("ranges along rays: held-out boards 1.9x closer than ...").
  std::string Describe() const;
};

LidarGeometryVerdict ClassifyLidarGeometry(const LidarCloud& cloud,
                                           const LidarGeometryOptions& options = {});

// The azimuth the cloud's returns cover (degrees, 0.5° cells occupied), up to 360.
double AzimuthCoverageDeg(const LidarCloud& cloud);

// How far the returns spread about their centre (the per-axis median): the 90th percentile of
// their distances to it, metres. 0 for an empty cloud.
double CloudExtentM(const LidarCloud& cloud);

}  // namespace calibench
