// Shared pieces of the cloud readers and writers (cloud_io.cpp, cloud_io_pcd.cpp). Not part of the
// public interface: include core/cloud.h instead.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/load_limits.h"
#include "core/lidar/cloud.h"
#include "core/lidar/point_times.h"

namespace calibench::cloud_io_detail {

enum class ScalarKind { kSigned, kUnsigned, kFloat };
struct ScalarType {
  ScalarKind kind = ScalarKind::kFloat;
  int bytes = 4;  // 1, 2, 4 or 8
};

// What a named field/property becomes in LidarCloud; the first six index value arrays.
enum FieldRole { kX = 0, kY, kZ, kIntensity, kRing, kRange, kVpX, kVpY, kVpZ, kTime, kIgnored };
inline constexpr int kNumRoles = 10;
// x, y, z, intensity (or "i"), ring, range, vp_x/y/z, the per-point time (`t`, as the dataset
// contract writes it, or velodyne's `time`); anything else (rgb, reflectivity, ...) is ignored.
FieldRole RoleOfName(std::string_view name);

// Reads one scalar stored at `data` in the given byte order, widened to double.
double ReadScalar(const char* data, ScalarType type, bool big_endian);

// Throws IoError "<file>: <problem>".
[[noreturn]] void Fail(const std::filesystem::path& path, const std::string& problem);

// The whole file; IoError when it is missing or unreadable.
std::string ReadWholeFile(const std::filesystem::path& path);

// Strict number parsing of one token (no leading/trailing garbage). Accepts nan/inf.
bool ParseDouble(std::string_view token, double* value);
bool ParseSize(std::string_view token, uint64_t* value);

// Splits on spaces/tabs; drops a trailing '\r'.
std::vector<std::string_view> SplitWords(std::string_view line);

// Collects points one by one, drops non-finite coordinates and validates ring ids.
class CloudBuilder {
 public:
  // `has[role]` tells which optional channels the file provides.
  CloudBuilder(const std::filesystem::path& path, const bool has[kNumRoles], size_t expected);
  // values[role] for the roles present; others are ignored.
  void Add(const double values[kNumRoles]);
  // The time field as the file declares it (when `has[kTime]`): how its values read as seconds
  // after the pair's lidar_stamp_ns is decided at Finish (core/lidar/point_times.h).
  void TimeFieldIs(PointTimeField field) { time_field_ = std::move(field); }
  // Keeps width x height only when it matches and nothing was dropped; IoError on no points.
  LidarCloud Finish(int width, int height);

 private:
  const std::filesystem::path& path_;
  bool has_intensity_, has_ring_, has_range_, has_viewpoint_, has_time_;
  PointTimeField time_field_{"t", false, "float"};
  std::vector<double> raw_times_;
  size_t seen_ = 0;
  size_t dropped_ = 0;
  LidarCloud cloud_;
};

// Writers: validated channel sizes, and the ring value as uint16 (IoError when out of range).
void CheckCloudForWriting(const std::filesystem::path& path, const LidarCloud& cloud);
uint16_t RingAsU16(const std::filesystem::path& path, int ring);
std::ofstream OpenForWriting(const std::filesystem::path& path);
void CloseAfterWriting(std::ofstream& out, const std::filesystem::path& path);

// Appends the raw bytes of a trivially copyable value (little-endian hosts only).
template <typename T>
void AppendBytes(std::string* out, T value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

LidarCloud LoadPcd(const std::filesystem::path& path, const LoadLimits& limits);
LidarCloud LoadPly(const std::filesystem::path& path, const LoadLimits& limits);

}  // namespace calibench::cloud_io_detail
