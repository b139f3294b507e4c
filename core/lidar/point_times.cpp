#include "core/lidar/point_times.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace calibench {
namespace {

struct Candidate {
  double seconds_per_unit;
  bool on_the_clock;
  const char* words;
};

// Floats: a relative field in seconds is by far the most common (velodyne, many drivers' `time`);
// absolute seconds (Hesai, Robosense), absolute nanoseconds (livox_ros_driver2). Integers count
// nanoseconds (Ouster's `t`, Livox's offset_time) after the stamp, else on the clock.
constexpr Candidate kFloatCandidates[] = {{1.0, false, "seconds after the stamp"},
                                          {1.0, true, "seconds on the LiDAR's clock"},
                                          {1e-9, true, "nanoseconds on the LiDAR's clock"},
                                          {1e-6, true, "microseconds on the LiDAR's clock"}};
constexpr Candidate kIntegerCandidates[] = {{1e-9, false, "nanoseconds after the stamp"},
                                            {1e-9, true, "nanoseconds on the LiDAR's clock"},
                                            {1e-6, true, "microseconds on the LiDAR's clock"}};

std::string Seconds(double s) {
  if (std::abs(s) < 5e-5) s = 0.0;  // no "-0.0000"
  char text[32];
  std::snprintf(text, sizeof(text), "%.4f", s);
  return text;
}

}  // namespace

bool PointTimeOptions::Check(std::string* why) const {
  if (max_span_s > 0 && std::isfinite(max_span_s)) return true;
  if (why) *why = "the longest span of a cloud's returns must be > 0 s";
  return false;
}

const std::vector<std::string>& PointTimeFieldNames() {
  static const std::vector<std::string> kNames = {
      "t", "time", "timestamp", "time_stamp", "offset_time", "time_offset", "point_time"};
  return kNames;
}

PointTimeReading ReadPointTimes(const PointTimeField& field, const std::vector<double>& raw,
                                std::optional<double> stamp_s, const PointTimeOptions& options) {
  PointTimeReading reading;
  const std::string what = "'" + field.name + "' (" + field.type + ")";
  if (raw.empty()) {
    reading.words = "per-point times from " + what + ": no returns to read";
    return reading;
  }
  double low = raw[0], high = raw[0];
  for (double v : raw) {
    if (!std::isfinite(v)) {
      reading.words = "per-point times from " + what +
                      " hold values that are not finite: each cloud is treated as instantaneous";
      return reading;
    }
    low = std::min(low, v), high = std::max(high, v);
  }
  const auto& candidates =
      field.integer
          ? std::vector<Candidate>(std::begin(kIntegerCandidates), std::end(kIntegerCandidates))
          : std::vector<Candidate>(std::begin(kFloatCandidates), std::end(kFloatCandidates));
  for (const Candidate& c : candidates) {
    if (c.on_the_clock && !stamp_s) continue;
    const double origin = c.on_the_clock ? *stamp_s : 0.0;
    // In long double: seconds on the clock (1.7e9) less the stamp keep their microseconds.
    const double first = static_cast<double>(static_cast<long double>(low) * c.seconds_per_unit -
                                             static_cast<long double>(origin));
    const double last = static_cast<double>(static_cast<long double>(high) * c.seconds_per_unit -
                                            static_cast<long double>(origin));
    if (std::abs(first) > options.max_span_s || std::abs(last) > options.max_span_s ||
        last - first > options.max_span_s)
      continue;
    reading.ok = true;
    reading.seconds_per_unit = c.seconds_per_unit;
    reading.on_the_clock = c.on_the_clock;
    reading.first_s = first, reading.last_s = last;
    reading.words = "per-point times from " + what + ", read as " + c.words + ": " +
                    Seconds(first) + " .. " + Seconds(last) + " s after the stamp";
    return reading;
  }
  char range[96];
  std::snprintf(range, sizeof(range), "%.6g .. %.6g", low, high);
  reading.words = "per-point times from " + what + " hold " + range +
                  ", which no unit puts within " + Seconds(options.max_span_s) +
                  " s of the cloud's stamp: each cloud is treated as instantaneous";
  return reading;
}

std::vector<float> PointTimesAfterStamp(const std::vector<double>& raw,
                                        const PointTimeReading& reading,
                                        std::optional<double> stamp_s) {
  std::vector<float> out;
  if (!reading.ok) return out;
  const long double origin = reading.on_the_clock && stamp_s ? *stamp_s : 0.0L;
  out.reserve(raw.size());
  for (double v : raw)
    out.push_back(
        static_cast<float>(static_cast<long double>(v) * reading.seconds_per_unit - origin));
  return out;
}

std::string DescribePointTimes(const std::vector<float>& time_s) {
  if (time_s.empty()) return "no per-point times: treated as instantaneous";
  const auto [low, high] = std::minmax_element(time_s.begin(), time_s.end());
  char text[128];
  std::snprintf(text, sizeof(text), "the returns span %.1f ms (%.4f .. %.4f s after the stamp)",
                (*high - *low) * 1e3, *low, *high);
  return text;
}

}  // namespace calibench
