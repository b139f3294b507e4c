#include "core/lidar/risley_pattern.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace calibench {
namespace {

Vec3 FromAzimuthElevation(double azimuth_rad, double elevation_rad) {
  return Vec3(std::cos(elevation_rad) * std::cos(azimuth_rad),
              std::cos(elevation_rad) * std::sin(azimuth_rad), std::sin(elevation_rad));
}

}  // namespace

RisleyPattern MakeRisleyPattern(const std::string& name) {
  RisleyPattern p;
  p.name = name;
  if (name == "mid40") return p;
  if (name == "avia") {
    p.half_fov_h_deg = 35.2;
    p.half_fov_v_deg = 38.6;
    p.points_per_s = 200000.0;
    p.prism1_hz = 97.3;
    p.prism2_hz = -61.9;
    p.lasers = 6;
    p.laser_spacing_deg = 2.0;  // assumed: a column spanning 10°, filling between the petals
    return p;
  }
  if (name == "mid360") {
    p.spinning = true;
    p.half_fov_v_deg = 29.5;
    p.centre_elevation_deg = 22.5;
    p.points_per_s = 200000.0;
    p.prism1_hz = 173.1;  // the elevation sweep's rate, incommensurate with the spin
    p.max_range_m = 40.0;
    p.min_range_m = 0.1;
    p.lasers = 4;
    return p;
  }
  throw std::invalid_argument("unknown Livox-class pattern \"" + name +
                              "\" (known: " + RisleyPatternNames() + ")");
}

std::string RisleyPatternNames() { return "mid40, avia, mid360"; }

bool InRisleyField(const RisleyPattern& pattern, const Vec3& direction) {
  const double horizontal = std::hypot(direction.x(), direction.y());
  const double elevation_deg = std::atan2(direction.z(), horizontal) * kRadToDeg;
  if (pattern.spinning)
    return std::abs(elevation_deg - pattern.centre_elevation_deg) <= pattern.half_fov_v_deg;
  if (!(direction.x() > 0.0)) return false;
  const double azimuth_deg = std::atan2(direction.y(), direction.x()) * kRadToDeg;
  const double u = azimuth_deg / pattern.half_fov_h_deg, v = elevation_deg / pattern.half_fov_v_deg;
  return u * u + v * v <= 1.0;
}

RisleyRays FireRisleyPattern(const RisleyPattern& pattern, double start_s, double duration_s) {
  RisleyRays rays;
  const long n = std::lround(duration_s * pattern.points_per_s);
  const int lasers = std::max(1, pattern.lasers);
  if (n <= 0) return rays;
  rays.directions.reserve(n);
  rays.time_offsets_s.reserve(n);
  rays.laser.reserve(n);
  const double w1 = 2.0 * M_PI * pattern.prism1_hz, w2 = 2.0 * M_PI * pattern.prism2_hz;
  for (int laser = 0; laser < lasers; ++laser) {
    // The lasers fire in turn: laser b's m-th ray is the (m·lasers + b)-th of the scanner.
    const double shift_deg = (laser - 0.5 * (lasers - 1)) * pattern.laser_spacing_deg;
    // The rosette shrinks by the largest shift, so that every laser's stays inside the field.
    const double max_shift_deg = 0.5 * (lasers - 1) * pattern.laser_spacing_deg;
    const double shrink =
        pattern.spinning ? 1.0 : std::max(0.0, 1.0 - max_shift_deg / pattern.half_fov_v_deg);
    const double phase = 2.0 * M_PI * laser / lasers;
    for (long k = laser; k < n; k += lasers) {
      const double dt = k / pattern.points_per_s, t = start_s + dt;
      Vec3 direction;
      if (pattern.spinning) {
        const double azimuth = 2.0 * M_PI * pattern.spin_hz * t;
        const double elevation =
            (pattern.centre_elevation_deg + pattern.half_fov_v_deg * std::sin(w1 * t + phase)) *
            kDegToRad;
        direction = FromAzimuthElevation(azimuth, elevation);
      } else {
        // Each wedge deflects the beam by half of the half field; their sum sweeps a rosette
        // that reaches the rim when the two deflections line up.
        const double u = 0.5 * (std::cos(w1 * t) + std::cos(w2 * t));
        const double v = 0.5 * (std::sin(w1 * t) + std::sin(w2 * t));
        direction =
            FromAzimuthElevation(shrink * u * pattern.half_fov_h_deg * kDegToRad,
                                 (shrink * v * pattern.half_fov_v_deg + shift_deg) * kDegToRad);
      }
      rays.directions.push_back(direction);
      rays.time_offsets_s.push_back(dt);
      rays.laser.push_back(laser);
    }
  }
  return rays;
}

}  // namespace calibench
