#include "core/lidar/board_returns.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace calibench {

BeamRays::BeamRays(const BeamTable& beams, double azimuth_offset_rad)
    : steps_(beams.azimuth_steps),
      azimuth_offset_rad_(azimuth_offset_rad),
      mirror_offset_m_(beams.swept ? beams.mirror_offset_m : Vec3::Zero()) {
  if (beams.rays) {
    fired_ = beams.rays;
  } else if (beams.risley) {
    RisleyRays fired =
        FireRisleyPattern(*beams.risley, azimuth_offset_rad / (2.0 * M_PI), beams.frame_s);
    for (double& t : fired.time_offsets_s) t /= beams.frame_s;
    fired_ = std::make_shared<const std::vector<Vec3>>(std::move(fired.directions));
    fired_fraction_ = std::make_shared<const std::vector<double>>(std::move(fired.time_offsets_s));
  }
  if (beams.Fired()) {
    steps_ = static_cast<int>(fired_->size());
    cos_elevation_ = {1.0};  // one "ring"
    sin_elevation_ = {0.0};
    return;
  }
  if (beams.nodding) {
    nodding_ = true;
    fan_rad_ = beams.elevations_rad;
    tilt_step_rad_ = beams.azimuth_steps > 1
                         ? (beams.tilt_last_rad - beams.tilt_first_rad) / (beams.azimuth_steps - 1)
                         : 0.0;
    tilt_first_rad_ = beams.tilt_first_rad + azimuth_offset_rad;
  }
  for (const double elevation : beams.elevations_rad) {
    cos_elevation_.push_back(std::cos(elevation));
    sin_elevation_.push_back(std::sin(elevation));
  }
}

double BeamRays::FiredFraction(int step) const {
  if (steps_ <= 0) return 0.0;
  const int wrapped = ((step % steps_) + steps_) % steps_;
  return fired_fraction_ ? (*fired_fraction_)[wrapped] : static_cast<double>(wrapped) / steps_;
}

double BeamRays::StepRad() const { return steps_ > 0 ? 2.0 * M_PI / steps_ : 0.0; }

BeamRay BeamRays::Ray(int ring, int step) const {
  const int wrapped = ((step % steps_) + steps_) % steps_;
  if (fired()) return {Vec3::Zero(), (*fired_)[wrapped]};
  if (nodding_) {
    // The fan's beam `ring` at tilt step `wrapped`: Ry(tilt) applied to the scan plane's ray and
    // to the mirror's offset.
    const double tilt = tilt_first_rad_ + tilt_step_rad_ * wrapped;
    const double ct = std::cos(tilt), st = std::sin(tilt);
    const double ca = std::cos(fan_rad_[ring]), sa = std::sin(fan_rad_[ring]);
    const Vec3& m = mirror_offset_m_;
    return {Vec3(ct * m.x() + st * m.z(), m.y(), -st * m.x() + ct * m.z()),
            Vec3(ct * ca, sa, -st * ca)};
  }
  const double azimuth = azimuth_offset_rad_ + 2.0 * M_PI * wrapped / steps_;
  const double cos_az = std::cos(azimuth), sin_az = std::sin(azimuth);
  // A swept scanner's rays start on its mirror, which the stage turns with the scan plane.
  const Vec3& m = mirror_offset_m_;
  return {Vec3(cos_az * m.x() - sin_az * m.y(), sin_az * m.x() + cos_az * m.y(), m.z()),
          Vec3(cos_elevation_[ring] * cos_az, cos_elevation_[ring] * sin_az, sin_elevation_[ring])};
}

std::optional<RectangleHit> HitRectangle(const BeamRay& ray, const LidarRectangle& rectangle) {
  const Mat3& axes = rectangle.lidar_from_rectangle.linear();
  const Vec3& centre = rectangle.lidar_from_rectangle.translation();
  const Vec3 normal = axes.col(2);
  const double denominator = normal.dot(ray.direction);
  if (std::abs(denominator) < 1e-12) return std::nullopt;
  const double range = normal.dot(centre - ray.origin) / denominator;
  if (!(range > 0.0)) return std::nullopt;
  const Vec3 local = ray.origin + range * ray.direction - centre;
  RectangleHit hit;
  hit.range_m = range;
  hit.xy = Vec2(axes.col(0).dot(local), axes.col(1).dot(local));
  hit.inside = std::abs(hit.xy.x()) <= rectangle.half_size_m.x() &&
               std::abs(hit.xy.y()) <= rectangle.half_size_m.y();
  return hit;
}

namespace {

// The steps [first, last] whose rays can reach the sheet: its corners' azimuths about the
// centre's, widened by what a swept scanner's mirror offset can add, plus one step each side.
// Every step when the sheet spans more than half the sweep (or hangs over the LiDAR).
std::pair<int, int> StepsOverSheet(const BeamRays& rays, const BeamTable& beams,
                                   const LidarRectangle& sheet, double azimuth_offset_rad) {
  // A rosette comes back anywhere; a nodding fan's steps are tilts, not azimuths.
  if (rays.fired() || rays.nodding()) return {0, rays.steps() - 1};
  const Pose& pose = sheet.lidar_from_rectangle;
  const Vec3& centre = pose.translation();
  const double centre_azimuth = std::atan2(centre.y(), centre.x());
  double half_span = 0.0, nearest_m = centre.head<2>().norm();
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Vec3 corner = pose * Vec3(sx * sheet.half_size_m.x(), sy * sheet.half_size_m.y(), 0.0);
      half_span = std::max(
          half_span, std::abs(std::remainder(std::atan2(corner.y(), corner.x()) - centre_azimuth,
                                             2.0 * M_PI)));
      nearest_m = std::min(nearest_m, corner.head<2>().norm());
    }
  }
  const double mirror_m = beams.swept ? beams.mirror_offset_m.head<2>().norm() : 0.0;
  if (nearest_m <= mirror_m + 1e-6) return {0, rays.steps() - 1};
  half_span += std::asin(std::min(1.0, mirror_m / nearest_m));
  if (half_span >= 0.5 * M_PI) return {0, rays.steps() - 1};
  const double step = rays.StepRad();
  const int first =
      static_cast<int>(std::floor((centre_azimuth - half_span - azimuth_offset_rad) / step)) - 1;
  const int last =
      static_cast<int>(std::ceil((centre_azimuth + half_span - azimuth_offset_rad) / step)) + 1;
  return {first, last};
}

// A learnt table's rays that can meet the sheet: those in the 1° cells its outline spans (its
// border sampled, widened by 2°), each with its neighbours in firing order (a crossing of the
// border pairs a ray on the sheet with the next), in firing order, each once. The elevation and
// azimuth bounds of a sheet's directions are those of its border unless it surrounds the vertical,
// where they are not bounded: false then (cast every ray), and for any other table.
bool LearntRaysNear(const BeamTable& beams, const LidarRectangle& sheet, std::vector<int>* near) {
  if (!beams.rays || !beams.ray_cells) return false;
  for (const double z : {1.0, -1.0}) {
    const auto hit = HitRectangle({Vec3::Zero(), Vec3(0, 0, z)}, sheet);
    if (hit && hit->inside) return false;
  }
  const Pose& pose = sheet.lidar_from_rectangle;
  const Vec3& centre = pose.translation();
  if (centre.norm() < 1e-6) return false;
  constexpr double kDeg = 180.0 / M_PI;
  const double centre_azimuth = std::atan2(centre.y(), centre.x());
  double az_lo = 180.0, az_hi = -180.0, el_lo = 90.0, el_hi = -90.0;  // azimuths about the centre's
  constexpr int kPerEdge = 32;
  const Vec2& h = sheet.half_size_m;
  const Vec2 corners[4] = {{-h.x(), -h.y()}, {h.x(), -h.y()}, {h.x(), h.y()}, {-h.x(), h.y()}};
  for (int edge = 0; edge < 4; ++edge) {
    for (int k = 0; k < kPerEdge; ++k) {
      const Vec2 xy = corners[edge] + (corners[(edge + 1) % 4] - corners[edge]) * k / kPerEdge;
      const Vec3 p = pose * Vec3(xy.x(), xy.y(), 0.0);
      const double range = p.norm();
      if (range < 1e-6) return false;
      const double azimuth =
          std::remainder(std::atan2(p.y(), p.x()) - centre_azimuth, 2.0 * M_PI) * kDeg;
      const double elevation = std::asin(std::clamp(p.z() / range, -1.0, 1.0)) * kDeg;
      az_lo = std::min(az_lo, azimuth);
      az_hi = std::max(az_hi, azimuth);
      el_lo = std::min(el_lo, elevation);
      el_hi = std::max(el_hi, elevation);
    }
  }
  if (az_hi - az_lo > 180.0) return false;
  constexpr double kMarginDeg = 2.0;
  const int e_first = std::max(0, static_cast<int>(std::floor(el_lo - kMarginDeg + 90.0)));
  const int e_last = std::min(179, static_cast<int>(std::floor(el_hi + kMarginDeg + 90.0)));
  const double a_centre = centre_azimuth * kDeg + 180.0;
  const int a_first = static_cast<int>(std::floor(a_centre + az_lo - kMarginDeg));
  const int a_last = static_cast<int>(std::floor(a_centre + az_hi + kMarginDeg));
  const LearntRayCells& cells = *beams.ray_cells;
  const int count = static_cast<int>(beams.rays->size());
  // Marked in a bitset and read back in order: a sheet near the scanner spans tens of thousands of
  // rays, and sorting their indices cost more than casting them.
  std::vector<std::uint64_t> marked((count + 63) / 64, 0);
  auto mark = [&marked](int k) { marked[k >> 6] |= std::uint64_t{1} << (k & 63); };
  for (int e = e_first; e <= e_last; ++e) {
    for (int a = a_first; a <= a_last; ++a) {
      const int cell = e * 360 + ((a % 360) + 360) % 360;
      for (int i = cells.start[cell]; i < cells.start[cell + 1]; ++i) {
        const int k = cells.by_cell[i];
        if (k > 0) mark(k - 1);
        mark(k);
        if (k + 1 < count) mark(k + 1);
      }
    }
  }
  near->clear();
  for (size_t word = 0; word < marked.size(); ++word)
    for (std::uint64_t bits = marked[word]; bits != 0; bits &= bits - 1)
      near->push_back(static_cast<int>(64 * word) + std::countr_zero(bits));
  return true;
}

}  // namespace

BoardReturns CastBoardReturns(const BeamTable& beams, const LidarRectangle& sheet,
                              double azimuth_offset_rad) {
  BoardReturns out;
  if (beams.azimuth_steps < 1 && !beams.Fired()) return out;
  const BeamRays rays(beams, azimuth_offset_rad);
  out.points_per_ring.assign(rays.rings(), 0);
  out.fired = rays.fired();
  const auto [first, last] = StepsOverSheet(rays, beams, sheet, azimuth_offset_rad);
  // Learnt rays: only those that can meet the sheet, the same returns and crossings as all of
  // them give (a gap in firing order is no crossing: neither side of it is on the sheet).
  std::vector<int> near;
  const bool indexed = LearntRaysNear(beams, sheet, &near);
  for (int ring = 0; ring < rays.rings(); ++ring) {
    Vec3 previous = Vec3::Zero();
    bool previous_on = false, previous_valid = false;
    const int casts = indexed ? static_cast<int>(near.size()) : last - first + 1;
    for (int i = 0; i < casts; ++i) {
      const int step = indexed ? near[i] : first + i;
      if (indexed && i > 0 && step != near[i - 1] + 1) previous_valid = false;
      const BeamRay ray = rays.Ray(ring, step);
      const auto hit = HitRectangle(ray, sheet);
      const bool valid = hit && hit->range_m >= kLidarMinRangeM && hit->range_m < beams.max_range_m;
      const Vec3 point = valid ? Vec3(ray.origin + hit->range_m * ray.direction) : Vec3::Zero();
      const bool on = valid && hit->inside;
      if (on) {
        out.points.push_back(point);
        out.ring.push_back(ring);
        ++out.points_per_ring[ring];
      }
      // A crossing of the sheet's edge: midway between the last return on the sheet and the
      // first beyond it, on the plane (as ExtractBoardEdgePoints measures it).
      if (valid && previous_valid && on != previous_on) {
        const Vec3& inside = on ? point : previous;
        const Vec3& outside = on ? previous : point;
        LidarEdgePoint edge;
        edge.point = 0.5 * (inside + outside);
        edge.along_ring = (outside - inside).normalized();
        edge.sigma_along_m = (outside - inside).norm() / std::sqrt(12.0);
        out.edges.push_back(edge);
      }
      previous = point;
      previous_on = on;
      previous_valid = valid;
    }
  }
  return out;
}

bool BoardReturnsRule::Check(std::string* why) const {
  if (min_rings < 1 || min_points_per_ring < 1 || min_points < 3) {
    *why = "board returns: min_rings >= 1, min_points_per_ring >= 1 and min_points >= 3";
    return false;
  }
  return true;
}

int BoardReturnsRule::RingsCovered(const BoardReturns& returns) const {
  if (returns.fired) return 0;
  return static_cast<int>(std::count_if(returns.points_per_ring.begin(),
                                        returns.points_per_ring.end(),
                                        [this](int n) { return n >= min_points_per_ring; }));
}

bool BoardReturnsRule::Met(const BoardReturns& returns, std::string* why) const {
  const int rings = RingsCovered(returns);
  const int points = static_cast<int>(returns.points.size());
  if ((returns.fired || rings >= min_rings) && points >= min_points) return true;
  if (why != nullptr) {
    char text[160];
    if (returns.fired) {
      std::snprintf(text, sizeof(text), "%d returns on the board, under the %d it needs", points,
                    min_points);
      *why = text;
      return false;
    }
    std::snprintf(text, sizeof(text),
                  "%d rings and %d returns on the board, under the %d rings (of %d+ returns each) "
                  "and %d returns it needs",
                  rings, points, min_rings, min_points_per_ring, min_points);
    *why = text;
  }
  return false;
}

}  // namespace calibench
