#include "core/guidance/detection_reach.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

namespace calibench {

bool DetectionReachOptions::Check(std::string* why) const {
  if (!(square_margin >= 1.0)) return *why = "square_margin must be >= 1", false;
  if (!(incidence_margin_deg >= 0)) return *why = "incidence_margin_deg must be >= 0", false;
  if (!(max_square_factor >= 1.0) || !(min_incidence_deg > 0 && min_incidence_deg < 90) ||
      !(min_off_axis_share > 0 && min_off_axis_share <= 1))
    return *why = "the plausibility bounds of a learned reach are out of range", false;
  return true;
}

double DetectableSquarePx(const BoardSpec& board) {
  if (board.type != BoardType::kCharuco || !(board.marker_size > 0)) return 8.0;
  // "DICT_5X5_100" -> 5 bits a side; the border adds one cell each side.
  int bits = 4;
  if (board.dictionary.size() > 5 && std::isdigit(static_cast<unsigned char>(board.dictionary[5])))
    bits = board.dictionary[5] - '0';
  return 1.5 * (bits + 2) * board.square_size / board.marker_size;
}

BoardAppearance AppearanceOf(const CameraModel& camera, const BoardSpec& board,
                             const Pose& cam_from_board) {
  BoardAppearance a;
  const Vec3 centre = cam_from_board.translation();
  a.distance_m = centre.norm();
  const Vec3 normal = cam_from_board.linear().col(2);
  a.incidence_deg = std::acos(std::min(1.0, std::abs(normal.dot(centre.normalized())))) * kRadToDeg;
  a.off_axis_deg = std::acos(std::clamp(centre.normalized().z(), -1.0, 1.0)) * kRadToDeg;
  const auto middle = camera.Project(centre);
  if (!middle) return a;  // behind the camera: no width
  double narrowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    const double angle = M_PI * k / 8.0;
    const Vec3 step = board.square_size * Vec3(std::cos(angle), std::sin(angle), 0.0);
    const auto end = camera.Project(cam_from_board * step);
    narrowest = std::min(narrowest, end ? (*end - *middle).norm() : 0.0);
  }
  a.square_px = narrowest;
  return a;
}

namespace {

// Where a pair's board stood, as a BoardSpec pose: its LiDAR plane's inlier centre and normal in
// the camera frame (the in-plane turn is arbitrary; AppearanceOf does not depend on it).
Pose PlacedFromLidar(const LidarPlaneFit& lidar, const Pose& cam_from_lidar) {
  const Vec3 centre = cam_from_lidar * lidar.inlier_centroid;
  Vec3 z = cam_from_lidar.linear() * lidar.plane.normal;  // towards the LiDAR
  if (z.dot(centre) < 0) z = -z;                          // BoardSpec's z: away from the camera
  const Vec3 x = (std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(z).normalized();
  Pose pose = Pose::Identity();
  pose.linear() << x, z.cross(x), z;
  pose.translation() = centre;
  return pose;
}

std::string MissWords(const BoardAppearance& a, const DetectionReach& reach) {
  char text[400];
  std::string words;
  auto add = [&](const std::string& part) { words += (words.empty() ? "" : "; ") + part; };
  if (a.square_px < reach.min_square_px) {
    std::snprintf(text, sizeof(text),
                  "board too small in the image at %.1f m (squares %.0f px wide; this rig's "
                  "detector needs about %.0f px)",
                  a.distance_m, a.square_px, reach.min_square_px);
    add(text);
  }
  if (a.incidence_deg > reach.max_incidence_deg) {
    std::snprintf(text, sizeof(text),
                  "board too oblique to the camera (%.0f deg off facing it; this rig's detector "
                  "reaches about %.0f deg)",
                  a.incidence_deg, reach.max_incidence_deg);
    add(text);
  }
  if (a.off_axis_deg > reach.max_off_axis_deg) {
    std::snprintf(text, sizeof(text),
                  "board too near the image's rim (%.0f deg off the optical axis; this rig's "
                  "detector reaches about %.0f deg)",
                  a.off_axis_deg, reach.max_off_axis_deg);
    add(text);
  }
  if (words.empty()) {
    std::snprintf(text, sizeof(text),
                  "the camera missed the board at %.1f m (squares %.0f px, %.0f deg off facing "
                  "it), within the reach measured on %d boards found: blur, light, or part of "
                  "the sheet outside the image?",
                  a.distance_m, a.square_px, a.incidence_deg, reach.boards_found);
    words = text;
  }
  return words;
}

// The limit on one quantity that misclassifies the fewest boards: found boards beyond it and
// missed ones within it (`upper`: the limit is a maximum). Candidates are the misses' values
// moved by `margin` towards the found side; ties go to the more cautious limit. `none` when no
// candidate beats leaving the quantity unlimited.
double BestLimit(const std::vector<double>& found, const std::vector<double>& missed, bool upper,
                 double margin, double none) {
  auto errors = [&](double limit) {
    int wrong = 0;
    for (double v : found) wrong += upper ? v > limit : v < limit;
    for (double v : missed) wrong += upper ? v <= limit : v >= limit;
    return wrong;
  };
  double best = none;
  int fewest = errors(none);
  for (double v : missed) {
    const double limit = upper ? v - margin : v * margin;
    const int wrong = errors(limit);
    if (wrong < fewest || (wrong == fewest && (upper ? limit < best : limit > best))) {
      fewest = wrong;
      best = limit;
    }
  }
  return best;
}

}  // namespace

DetectionReach LearnDetectionReach(const CameraModel& camera, const BoardSpec& board,
                                   const std::vector<PairFeatures>& pairs,
                                   const std::optional<Pose>& cam_from_lidar,
                                   const DetectionReachOptions& options,
                                   std::vector<MissedBoard>* missed) {
  DetectionReach reach;
  std::vector<BoardAppearance> found;
  std::vector<MissedBoard> misses;
  for (const PairFeatures& p : pairs) {
    if (p.camera) {
      found.push_back(AppearanceOf(camera, board, p.camera->cam_from_board));
    } else if (p.lidar && cam_from_lidar && !p.input_error && p.reason.rfind("camera:", 0) == 0) {
      MissedBoard m;
      m.id = p.id;
      m.appearance = AppearanceOf(camera, board, PlacedFromLidar(*p.lidar, *cam_from_lidar));
      misses.push_back(m);
    }
  }
  reach.boards_found = static_cast<int>(found.size());
  reach.boards_missed = static_cast<int>(misses.size());
  // One quantity after the other, each on the misses the ones before leave unexplained: size
  // first (distance, tilt and the lens's scale all shrink the squares), then tilt, then the rim.
  std::vector<const MissedBoard*> open;
  for (const MissedBoard& m : misses) open.push_back(&m);
  auto values = [](const auto& list, auto field) {
    std::vector<double> out;
    for (const auto& item : list) out.push_back(field(item));
    return out;
  };
  // Only misses a quantity can plausibly explain count for it.
  const double widest_square = options.max_square_factor * DetectableSquarePx(board);
  const auto half_width_ray = camera.Unproject(Vec2(0.0, 0.5 * camera.height));
  const double half_field_deg =
      half_width_ray
          ? std::acos(std::clamp(half_width_ray->normalized().z(), -1.0, 1.0)) * kRadToDeg
          : 90.0;
  const double least_off_axis = options.min_off_axis_share * half_field_deg;
  auto plausible = [&](double limit, double bound, bool upper, double none) {
    return (upper ? limit >= bound : limit <= bound) ? limit : none;
  };
  if (!found.empty() && !open.empty()) {
    reach.min_square_px = plausible(
        BestLimit(values(found, [](const BoardAppearance& a) { return a.square_px; }),
                  values(open, [](const MissedBoard* m) { return m->appearance.square_px; }),
                  /*upper=*/false, options.square_margin, 0.0),
        widest_square, false, 0.0);
    std::erase_if(
        open, [&](const MissedBoard* m) { return m->appearance.square_px < reach.min_square_px; });
    reach.max_incidence_deg = plausible(
        BestLimit(values(found, [](const BoardAppearance& a) { return a.incidence_deg; }),
                  values(open, [](const MissedBoard* m) { return m->appearance.incidence_deg; }),
                  /*upper=*/true, options.incidence_margin_deg, 90.0),
        options.min_incidence_deg, true, 90.0);
    std::erase_if(open, [&](const MissedBoard* m) {
      return m->appearance.incidence_deg > reach.max_incidence_deg;
    });
    reach.max_off_axis_deg = plausible(
        BestLimit(values(found, [](const BoardAppearance& a) { return a.off_axis_deg; }),
                  values(open, [](const MissedBoard* m) { return m->appearance.off_axis_deg; }),
                  /*upper=*/true, options.incidence_margin_deg, 180.0),
        least_off_axis, true, 180.0);
  }
  for (MissedBoard& m : misses) m.words = MissWords(m.appearance, reach);
  if (missed) *missed = std::move(misses);
  return reach;
}

}  // namespace calibench
