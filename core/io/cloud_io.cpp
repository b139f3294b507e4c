// LoadCloud dispatch, the helpers shared by all cloud formats, and KITTI .bin.
#include "core/io/cloud_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/base/notice.h"
#include "core/io/cloud_io_internal.h"
#include "core/lidar/cloud.h"

namespace calibench {
namespace cloud_io_detail {

static_assert(std::endian::native == std::endian::little,
              "the binary readers and writers assume a little-endian host");

FieldRole RoleOfName(std::string_view name) {
  if (name == "x") return kX;
  if (name == "y") return kY;
  if (name == "z") return kZ;
  if (name == "intensity" || name == "i") return kIntensity;
  if (name == "ring") return kRing;
  if (name == "range") return kRange;
  if (name == "vp_x") return kVpX;
  if (name == "vp_y") return kVpY;
  if (name == "vp_z") return kVpZ;
  if (name == "t" || name == "time") return kTime;
  return kIgnored;
}

namespace {

template <typename T>
T LoadAs(const char* data, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, data, sizeof(T));
  if (big_endian) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

}  // namespace

namespace {

// An integer of 1, 2, 4 or 8 bytes as the matching type of the family (signed or unsigned).
template <typename T8, typename T16, typename T32, typename T64>
double ReadInteger(const char* data, int bytes, bool big_endian) {
  switch (bytes) {
    case 1:
      return LoadAs<T8>(data, big_endian);
    case 2:
      return LoadAs<T16>(data, big_endian);
    case 4:
      return LoadAs<T32>(data, big_endian);
    default:
      return static_cast<double>(LoadAs<T64>(data, big_endian));
  }
}

}  // namespace

double ReadScalar(const char* data, ScalarType type, bool big_endian) {
  switch (type.kind) {
    case ScalarKind::kFloat:
      return type.bytes == 4 ? LoadAs<float>(data, big_endian) : LoadAs<double>(data, big_endian);
    case ScalarKind::kSigned:
      return ReadInteger<int8_t, int16_t, int32_t, int64_t>(data, type.bytes, big_endian);
    case ScalarKind::kUnsigned:
      return ReadInteger<uint8_t, uint16_t, uint32_t, uint64_t>(data, type.bytes, big_endian);
  }
  throw std::logic_error("ReadScalar: unknown scalar kind");
}

void Fail(const std::filesystem::path& path, const std::string& problem) {
  throw IoError(path.string() + ": " + problem);
}

std::string ReadWholeFile(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);  // follows symbolic links
  if (status.type() == fs::file_type::not_found) Fail(path, "file does not exist");
  if (ec) Fail(path, "cannot read: " + ec.message());  // e.g. a loop of symbolic links
  if (fs::is_directory(status)) Fail(path, "is a directory, not a cloud file");
  // A FIFO would block forever and a device like /dev/zero would never end.
  if (!fs::is_regular_file(status))
    Fail(path, "is not a regular file (a FIFO or a device?); clouds are read from files");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) Fail(path, "cannot read its size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, std::string("cannot open for reading: ") + std::strerror(errno));
  // Read straight into the string that the parsers read: no stream buffer in between.
  std::string bytes(static_cast<size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size)
    Fail(path, "read error (" + std::to_string(in.gcount()) + " of " + std::to_string(size) +
                   " bytes; did the file change while it was read?)");
  return bytes;
}

bool ParseDouble(std::string_view token, double* value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;  // from_chars rejects '+', some writers emit it
  const auto result = std::from_chars(begin, end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

bool ParseSize(std::string_view token, uint64_t* value) {
  const auto result = std::from_chars(token.data(), token.data() + token.size(), *value);
  return result.ec == std::errc() && result.ptr == token.data() + token.size();
}

std::vector<std::string_view> SplitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

CloudBuilder::CloudBuilder(const std::filesystem::path& path, const bool has[kNumRoles],
                           size_t expected)
    : path_(path),
      has_intensity_(has[kIntensity]),
      has_ring_(has[kRing]),
      has_range_(has[kRange]),
      has_viewpoint_(has[kVpX] && has[kVpY] && has[kVpZ]),
      has_time_(has[kTime]) {
  cloud_.points.reserve(expected);
  if (has_intensity_) cloud_.intensity.reserve(expected);
  if (has_ring_) cloud_.ring.reserve(expected);
  if (has_range_) cloud_.range.reserve(expected);
  if (has_viewpoint_) cloud_.viewpoint.reserve(expected);
  if (has_time_) raw_times_.reserve(expected);
}

void CloudBuilder::Add(const double values[kNumRoles]) {
  const size_t index = seen_++;
  const Eigen::Vector3f point(static_cast<float>(values[kX]), static_cast<float>(values[kY]),
                              static_cast<float>(values[kZ]));
  if (!point.allFinite()) {
    ++dropped_;
    return;
  }
  cloud_.points.push_back(point);
  if (has_intensity_) cloud_.intensity.push_back(static_cast<float>(values[kIntensity]));
  if (has_ring_) {
    const double ring = values[kRing];
    // Float ring fields exist (some drivers); they must still hold a laser index.
    if (!std::isfinite(ring) || ring < 0 || ring > 65535 || ring != std::round(ring)) {
      std::ostringstream problem;
      problem << "point " << index << " has ring " << ring << ", not a laser index";
      Fail(path_, problem.str());
    }
    cloud_.ring.push_back(static_cast<int>(ring));
  }
  if (has_range_) cloud_.range.push_back(static_cast<float>(values[kRange]));
  if (has_viewpoint_) {
    const Eigen::Vector3f viewpoint(static_cast<float>(values[kVpX]),
                                    static_cast<float>(values[kVpY]),
                                    static_cast<float>(values[kVpZ]));
    if (!viewpoint.allFinite())
      Fail(path_, "point " + std::to_string(index) + " has a viewpoint that is not finite");
    cloud_.viewpoint.push_back(viewpoint);
  }
  if (has_time_) raw_times_.push_back(values[kTime]);
}

LidarCloud CloudBuilder::Finish(int width, int height) {
  if (cloud_.points.empty()) {
    Fail(path_, seen_ == 0 ? "contains no points"
                           : "none of its " + std::to_string(seen_) + " points has finite x, y, z");
  }
  if (has_time_) {
    // A file has no clock of its own: its times count from the pair's lidar_stamp_ns.
    const PointTimeReading reading = ReadPointTimes(time_field_, raw_times_, std::nullopt);
    cloud_.time_s = PointTimesAfterStamp(raw_times_, reading, std::nullopt);
    if (!reading.ok) NoteOnce("cloud-point-times", path_.string() + ": " + reading.words);
  }
  const bool keep_grid = dropped_ == 0 && height > 1 &&
                         static_cast<size_t>(width) * static_cast<size_t>(height) == seen_;
  cloud_.width = keep_grid ? width : static_cast<int>(cloud_.points.size());
  cloud_.height = keep_grid ? height : 1;
  return std::move(cloud_);
}

void CheckCloudForWriting(const std::filesystem::path& path, const LidarCloud& cloud) {
  const size_t n = cloud.size();
  if (cloud.HasIntensity() && cloud.intensity.size() != n)
    Fail(path, "cannot write: intensity has " + std::to_string(cloud.intensity.size()) +
                   " values for " + std::to_string(n) + " points");
  if (cloud.HasRing() && cloud.ring.size() != n)
    Fail(path, "cannot write: ring has " + std::to_string(cloud.ring.size()) + " values for " +
                   std::to_string(n) + " points");
  if (!cloud.range.empty() && cloud.range.size() != n)
    Fail(path, "cannot write: range has " + std::to_string(cloud.range.size()) + " values for " +
                   std::to_string(n) + " points");
  if (cloud.HasViewpoint() && cloud.viewpoint.size() != n)
    Fail(path, "cannot write: viewpoint has " + std::to_string(cloud.viewpoint.size()) +
                   " values for " + std::to_string(n) + " points");
  if (cloud.HasTime() && cloud.time_s.size() != n)
    Fail(path, "cannot write: time has " + std::to_string(cloud.time_s.size()) + " values for " +
                   std::to_string(n) + " points");
}

uint16_t RingAsU16(const std::filesystem::path& path, int ring) {
  if (ring < 0 || ring > 65535)
    Fail(path, "cannot write ring " + std::to_string(ring) + " as uint16");
  return static_cast<uint16_t>(ring);
}

std::ofstream OpenForWriting(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) Fail(path, std::string("cannot open for writing: ") + std::strerror(errno));
  return out;
}

void CloseAfterWriting(std::ofstream& out, const std::filesystem::path& path) {
  out.close();
  if (!out) Fail(path, "write failed (disk full or I/O error)");
}

namespace {

// KITTI velodyne .bin: a headerless array of float32 x y z reflectance.
LidarCloud LoadKittiBin(const std::filesystem::path& path, const LoadLimits& limits) {
  constexpr size_t kRecord = 4 * sizeof(float);
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec)  // the size is its header: refused before it is read
    CheckLoadLimit(path, "the point count (file size / 16)",
                   static_cast<std::int64_t>(size / kRecord), limits.max_cloud_points,
                   "max_cloud_points");
  const std::string bytes = ReadWholeFile(path);
  if (bytes.size() % kRecord != 0)
    Fail(path, "size " + std::to_string(bytes.size()) +
                   " bytes is not a multiple of 16 (float32 x y z intensity per point)");
  const size_t n = bytes.size() / kRecord;
  const bool has[kNumRoles] = {true, true, true, true, false, false};
  CloudBuilder builder(path, has, n);
  double values[kNumRoles] = {};
  constexpr ScalarType kF4{ScalarKind::kFloat, 4};
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 4; ++k)
      values[k] = ReadScalar(bytes.data() + i * kRecord + k * sizeof(float), kF4, false);
    builder.Add(values);
  }
  return builder.Finish(static_cast<int>(n), 1);
}

std::string LowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace
}  // namespace cloud_io_detail

LidarCloud LoadCloud(const std::filesystem::path& path, const LoadLimits& limits) {
  const std::string ext = cloud_io_detail::LowerExtension(path);
  if (ext == ".pcd") return cloud_io_detail::LoadPcd(path, limits);
  if (ext == ".ply") return cloud_io_detail::LoadPly(path, limits);
  if (ext == ".bin") return cloud_io_detail::LoadKittiBin(path, limits);
  cloud_io_detail::Fail(path, "unknown cloud extension '" + path.extension().string() +
                                  "' (expected .pcd, .ply or .bin)");
}

// KITTI has no "no intensity" variant: a cloud without intensity is written with 0, the value
// KITTI tools read as "no return strength".
void SaveKittiBin(const std::filesystem::path& path, const LidarCloud& cloud) {
  using namespace cloud_io_detail;
  CheckCloudForWriting(path, cloud);
  std::string bytes;
  bytes.reserve(cloud.size() * 4 * sizeof(float));
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int k = 0; k < 3; ++k) AppendBytes(&bytes, cloud.points[i][k]);
    AppendBytes(&bytes, cloud.HasIntensity() ? cloud.intensity[i] : 0.0f);
  }
  std::ofstream out = OpenForWriting(path);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  CloseAfterWriting(out, path);
}

}  // namespace calibench
