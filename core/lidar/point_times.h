// Each return's own time (docs/architecture.md "Time"): drivers write it in a field of their own
// naming, unit and origin — velodyne_pointcloud's `time` (float32 s after the stamp, negative when
// the driver stamps the sweep's last packet), Ouster's `t` (uint32 ns after the stamp),
// Hesai's and Robosense's `timestamp` (float64 s on the clock), livox_ros_driver2's `timestamp`
// (float64 ns on the clock), Luminar's `time_sec` + `time_nsec`, a Livox CustomMsg's
// `offset_time` (ns after its timebase). The reading here tells the unit and the origin from the
// field's type and the values' spread, and turns them into LidarCloud::time_s: seconds after the
// cloud's stamp. What it decided is said in words, once per source.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace calibench {

struct PointTimeOptions {
  // The longest a cloud's returns may span (seconds): a spinning LiDAR's sweep takes 0.05-0.2 s,
  // a Livox frame 0.1 s, a line scanner on a rotary stage some seconds. A reading whose returns
  // lie farther than this from the stamp is not the unit it was tried as.
  double max_span_s = 60.0;
  bool Check(std::string* why) const;
};

// A time field as a message or file declares it.
struct PointTimeField {
  std::string name;      // "time", "t", "timestamp", "time_sec+time_nsec", "offset_time"
  bool integer = false;  // an integer type (its values are counts of a small unit)
  std::string type;      // as the source names it ("FLOAT32", "UINT32", "F4"): for the words
};

// The field names drivers give their per-point times, most specific first (Luminar's pair of
// fields is decided by the decoders themselves).
const std::vector<std::string>& PointTimeFieldNames();

struct PointTimeReading {
  bool ok = false;
  double seconds_per_unit = 1.0;
  bool on_the_clock = false;           // values are times on the LiDAR's clock, not after the stamp
  double first_s = 0.0, last_s = 0.0;  // the returns' span after the stamp
  // "per-point times from 'time' (FLOAT32): seconds after the stamp, -0.0995 .. 0.0000 s" or, when
  // !ok, why the field was not read ("... fits no unit: each cloud is treated as instantaneous").
  std::string words;
};

// Decides how `raw` values read as seconds after `stamp_s` (the cloud's stamp on the LiDAR's
// clock, seconds; nullopt where none is known: a file's field, which the dataset contract makes
// seconds after the pair's lidar_stamp_ns). Floats are tried as seconds after the stamp, then as
// seconds, nanoseconds and microseconds on the clock; integers as nanoseconds after the stamp,
// then on the clock. The first whose returns all lie within max_span_s of the stamp wins.
PointTimeReading ReadPointTimes(const PointTimeField& field, const std::vector<double>& raw,
                                std::optional<double> stamp_s,
                                const PointTimeOptions& options = {});

// raw values -> seconds after the stamp, as `reading` decided (empty when !reading.ok).
std::vector<float> PointTimesAfterStamp(const std::vector<double>& raw,
                                        const PointTimeReading& reading,
                                        std::optional<double> stamp_s);

// What a cloud's times say, for a summary: "the returns span 99.5 ms (-0.0995 .. 0.0000 s after
// the stamp)", or that it has none and is treated as instantaneous.
std::string DescribePointTimes(const std::vector<float>& time_s);

}  // namespace calibench
