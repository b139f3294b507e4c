#include "core/recording/ros_messages.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/io/camera_file.h"
#include "core/lidar/point_times.h"
#include "core/recording/ros_message_cursor.h"

namespace calibench {
namespace {

constexpr const char* kNoTimeFieldWords = "each cloud is treated as instantaneous";

// The cursor over a message and its checks: core/recording/ros_message_cursor.h.
using ros_detail::Bad;
using ros_detail::ByteSwapped;
using ros_detail::CheckRows;
using ros_detail::MessageCursor;
using ros_detail::ReadHeader;

// sensor_msgs/PointField datatypes.
enum PointFieldType : std::uint8_t {
  kInt8 = 1,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};
constexpr const char* kPointFieldNames[] = {"?",     "INT8",   "UINT8",   "INT16",  "UINT16",
                                            "INT32", "UINT32", "FLOAT32", "FLOAT64"};
int PointFieldSize(std::uint8_t type) {
  constexpr int sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return type >= 1 && type <= 8 ? sizes[type] : 0;
}

struct PointField {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t type = 0;
  std::uint32_t count = 1;
};

template <typename T>
double Load(const std::uint8_t* at, bool swap) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return static_cast<double>(swap ? ByteSwapped(value) : value);
}

double ReadField(const std::uint8_t* point, const PointField& field, bool swap) {
  const std::uint8_t* at = point + field.offset;
  switch (field.type) {
    case kInt8:
      return static_cast<std::int8_t>(*at);
    case kUint8:
      return *at;
    case kInt16:
      return Load<std::int16_t>(at, swap);
    case kUint16:
      return Load<std::uint16_t>(at, swap);
    case kInt32:
      return Load<std::int32_t>(at, swap);
    case kUint32:
      return Load<std::uint32_t>(at, swap);
    case kFloat32:
      return Load<float>(at, swap);
    default:
      return Load<double>(at, swap);
  }
}

const PointField* FindField(const std::vector<PointField>& fields,
                            std::initializer_list<const char*> names) {
  for (const char* name : names)
    for (const PointField& field : fields)
      if (field.name == name) return &field;
  return nullptr;
}

std::vector<PointField> ReadPointFields(MessageCursor& cursor) {
  const std::uint32_t count = cursor.Read<std::uint32_t>();
  if (count > 1024) Bad("PointCloud2: " + std::to_string(count) + " fields");
  std::vector<PointField> fields(count);
  for (PointField& field : fields) {
    field.name = cursor.String("a field name");
    field.offset = cursor.Read<std::uint32_t>();
    field.type = cursor.Read<std::uint8_t>();
    field.count = cursor.Read<std::uint32_t>();
    if (PointFieldSize(field.type) == 0)
      Bad("PointCloud2: field '" + field.name + "' has datatype " + std::to_string(field.type) +
          ", which sensor_msgs/PointField does not define");
  }
  return fields;
}

// Stores the returns laser by laser (stable: each laser's in firing order), `line` holding each
// return's laser. A Livox driver interleaves its lasers' returns; a beam's path is one laser's.
template <typename Extra>
void OrderByLaserLine(const std::vector<int>& line, LidarCloud* cloud, std::vector<Extra>* extra) {
  if (line.empty() || std::all_of(line.begin(), line.end(), [&](int l) { return l == line[0]; }))
    return;
  std::vector<std::size_t> order(line.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return line[a] < line[b]; });
  auto permute = [&](auto& values) {
    if (values.size() != order.size()) return;
    std::remove_reference_t<decltype(values)> sorted;
    sorted.reserve(values.size());
    for (std::size_t i : order) sorted.push_back(values[i]);
    values = std::move(sorted);
  };
  permute(cloud->points);
  permute(cloud->intensity);
  permute(cloud->time_s);
  if (extra) permute(*extra);
}

bool IsIntegerField(const PointField& field) {
  return field.type != kFloat32 && field.type != kFloat64;
}

// The driver's per-point time field (point_times.h): Luminar's two fields as one value in seconds
// on the clock, else the first of PointTimeFieldNames.
struct TimeFields {
  const PointField* seconds = nullptr;      // time_sec (Luminar), else the one field
  const PointField* nanoseconds = nullptr;  // time_nsec (Luminar)
  PointTimeField declared;

  explicit TimeFields(const std::vector<PointField>& fields) {
    const PointField* sec = FindField(fields, {"time_sec"});
    const PointField* nsec = FindField(fields, {"time_nsec"});
    if (sec && nsec) {
      seconds = sec, nanoseconds = nsec;
      declared = {"time_sec+time_nsec", false,
                  std::string(kPointFieldNames[sec->type]) + "+" + kPointFieldNames[nsec->type]};
      return;
    }
    for (const std::string& name : PointTimeFieldNames())
      if (const PointField* field = FindField(fields, {name.c_str()})) {
        seconds = field;
        declared = {field->name, IsIntegerField(*field), kPointFieldNames[field->type]};
        return;
      }
  }
  double Read(const std::uint8_t* point, bool swap) const {
    const double value = ReadField(point, *seconds, swap);
    return nanoseconds ? value + 1e-9 * ReadField(point, *nanoseconds, swap) : value;
  }
};

void FillCloud(std::span<const std::uint8_t> data, const std::vector<PointField>& fields,
               std::uint32_t width, std::uint32_t height, std::uint32_t point_step,
               std::uint32_t row_step, bool swap, std::int64_t stamp_ns, LidarCloud* cloud,
               std::string* point_times) {
  const PointField* x = FindField(fields, {"x"});
  const PointField* y = FindField(fields, {"y"});
  const PointField* z = FindField(fields, {"z"});
  if (!x || !y || !z) Bad("PointCloud2: no x, y and z fields");
  const PointField* intensity = FindField(fields, {"intensity", "reflectivity", "i"});
  const PointField* ring = FindField(fields, {"ring", "laser_id", "channel"});
  // A Livox driver's PointCloud2 names its laser "line": not a ring (its returns follow the
  // rosette, not a cone), but the order its beam's path is stored in.
  const PointField* line = ring ? nullptr : FindField(fields, {"line"});
  // Each return's ray origin, as PCL's PointWithViewpoint names it (core/lidar/cloud.h).
  const PointField* vp_x = FindField(fields, {"vp_x"});
  const PointField* vp_y = FindField(fields, {"vp_y"});
  const PointField* vp_z = FindField(fields, {"vp_z"});
  const bool viewpoint = vp_x && vp_y && vp_z;
  const TimeFields time(fields);
  std::vector<double> raw_times;
  std::vector<int> lines;
  const std::size_t total = static_cast<std::size_t>(width) * height;
  if (total == 0) return;  // no points: not 4 billion empty rows walked through
  cloud->points.reserve(total);
  if (intensity) cloud->intensity.reserve(total);
  if (ring) cloud->ring.reserve(total);
  if (viewpoint) cloud->viewpoint.reserve(total);
  for (std::uint32_t row = 0; row < height; ++row) {
    const std::uint8_t* row_start = data.data() + static_cast<std::size_t>(row) * row_step;
    for (std::uint32_t column = 0; column < width; ++column) {
      const std::uint8_t* point = row_start + static_cast<std::size_t>(column) * point_step;
      const Eigen::Vector3f xyz(static_cast<float>(ReadField(point, *x, swap)),
                                static_cast<float>(ReadField(point, *y, swap)),
                                static_cast<float>(ReadField(point, *z, swap)));
      if (!xyz.allFinite()) continue;
      cloud->points.push_back(xyz);
      if (intensity)
        cloud->intensity.push_back(static_cast<float>(ReadField(point, *intensity, swap)));
      if (ring) {
        // The rule of the cloud files (cloud_io.cpp): a ring is a laser index, 0 .. 65535.
        const double index = ReadField(point, *ring, swap);
        if (!std::isfinite(index) || index < 0 || index > 65535 || index != std::round(index))
          Bad("PointCloud2: point " + std::to_string(cloud->points.size() - 1) + " has " +
              ring->name + " " + std::to_string(index) + ", not a laser index");
        cloud->ring.push_back(static_cast<int>(index));
      }
      if (line) lines.push_back(static_cast<int>(ReadField(point, *line, swap)));
      if (time.seconds) raw_times.push_back(time.Read(point, swap));
      if (viewpoint) {
        const Eigen::Vector3f origin(static_cast<float>(ReadField(point, *vp_x, swap)),
                                     static_cast<float>(ReadField(point, *vp_y, swap)),
                                     static_cast<float>(ReadField(point, *vp_z, swap)));
        if (!origin.allFinite())
          Bad("PointCloud2: point " + std::to_string(cloud->points.size() - 1) +
              " has a viewpoint that is not finite");
        cloud->viewpoint.push_back(origin);
      }
    }
  }
  if (time.seconds) {
    const std::optional<double> stamp_s = static_cast<double>(stamp_ns) * 1e-9;
    const PointTimeReading reading = ReadPointTimes(time.declared, raw_times, stamp_s);
    cloud->time_s = PointTimesAfterStamp(raw_times, reading, stamp_s);
    *point_times = reading.words;
  } else {
    *point_times = "no per-point time field (" + std::string(kNoTimeFieldWords) + ")";
  }
  OrderByLaserLine<int>(lines, cloud, nullptr);
  const bool complete = cloud->points.size() == total;
  cloud->width =
      complete && height > 1 ? static_cast<int>(width) : static_cast<int>(cloud->points.size());
  cloud->height = complete && height > 1 ? static_cast<int>(height) : 1;
}

}  // namespace

RosHeader DecodeRosHeader(std::span<const std::uint8_t> data, MessageEncoding encoding) {
  MessageCursor cursor(data, encoding, "the message header");
  return ReadHeader(cursor, encoding);
}

PointCloud2Message DecodePointCloud2(std::span<const std::uint8_t> data, MessageEncoding encoding,
                                     const LoadLimits& limits) {
  MessageCursor cursor(data, encoding, "PointCloud2");
  PointCloud2Message message;
  message.header = ReadHeader(cursor, encoding);
  const std::uint32_t height = cursor.Read<std::uint32_t>();
  const std::uint32_t width = cursor.Read<std::uint32_t>();
  const std::vector<PointField> fields = ReadPointFields(cursor);
  const bool big_endian = cursor.Read<std::uint8_t>() != 0;
  const std::uint32_t point_step = cursor.Read<std::uint32_t>();
  const std::uint32_t row_step = cursor.Read<std::uint32_t>();
  const std::span<const std::uint8_t> points = cursor.ByteSequence("the point data");
  for (const PointField& field : fields) {
    message.fields += (message.fields.empty() ? "" : " ") + field.name + ":" +
                      kPointFieldNames[field.type] + "@" + std::to_string(field.offset);
    if (static_cast<std::uint64_t>(field.offset) +
            PointFieldSize(field.type) * std::max<std::uint64_t>(field.count, 1) >
        point_step)
      Bad("PointCloud2: field '" + field.name + "' at byte " + std::to_string(field.offset) +
          " lies beyond point_step " + std::to_string(point_step));
  }
  // Both factors are uint32: their product always fits in 64 unsigned bits.
  const std::uint64_t declared = static_cast<std::uint64_t>(width) * height;
  if (declared > static_cast<std::uint64_t>(limits.max_cloud_points))
    Bad("PointCloud2: " + std::to_string(declared) + " points is over the limit of " +
        std::to_string(limits.max_cloud_points) + " (max_cloud_points)");
  CheckRows("PointCloud2", "row_step", row_step, "width x point_step",
            static_cast<std::uint64_t>(width) * point_step, height, points.size());
  message.declared_points = static_cast<int>(declared);
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  FillCloud(points, fields, width, height, point_step, row_step, swap, message.header.stamp_ns,
            &message.cloud, &message.point_times);
  return message;
}

CameraInfoMessage DecodeCameraInfo(std::span<const std::uint8_t> data, MessageEncoding encoding) {
  MessageCursor cursor(data, encoding, "CameraInfo");
  CameraInfoMessage message;
  message.header = ReadHeader(cursor, encoding);
  const std::uint32_t height = cursor.Read<std::uint32_t>();
  const std::uint32_t width = cursor.Read<std::uint32_t>();
  message.distortion_model = cursor.String("the distortion model");
  const std::uint32_t count = cursor.Read<std::uint32_t>();
  if (count > 64) Bad("CameraInfo: " + std::to_string(count) + " distortion coefficients");
  std::vector<double> d(count);
  cursor.ReadDoubles(d.data(), count);
  double k[9];
  cursor.ReadDoubles(k, 9);
  if (width == 0 || height == 0 || width > 1u << 20 || height > 1u << 20)
    Bad("CameraInfo: image size " + std::to_string(width) + " x " + std::to_string(height));
  if (k[0] == 0 && k[4] == 0)
    Bad("CameraInfo: K has no focal length (the camera driver publishes no calibration)");
  try {
    message.camera = CameraFromCameraInfo(message.distortion_model, static_cast<int>(width),
                                          static_cast<int>(height), k, d);
  } catch (const std::invalid_argument& error) {
    Bad(std::string("CameraInfo: ") + error.what());
  }
  return message;
}

LivoxCustomMessage DecodeLivoxCustomMsg(std::span<const std::uint8_t> data,
                                        MessageEncoding encoding, const LoadLimits& limits) {
  const char* type = "Livox CustomMsg";
  MessageCursor cursor(data, encoding, type);
  LivoxCustomMessage message;
  message.header = ReadHeader(cursor, encoding);
  message.timebase_ns = cursor.Read<std::uint64_t>();
  const std::uint32_t point_num = cursor.Read<std::uint32_t>();
  message.lidar_id = cursor.Read<std::uint8_t>();
  for (int k = 0; k < 3; ++k) cursor.Read<std::uint8_t>();  // rsvd
  const std::uint32_t count = cursor.Read<std::uint32_t>();
  if (count != point_num)
    Bad(std::string(type) + ": point_num " + std::to_string(point_num) + " but " +
        std::to_string(count) + " points");
  if (count > limits.max_cloud_points)
    Bad(std::string(type) + ": " + std::to_string(count) + " points, more than the " +
        std::to_string(limits.max_cloud_points) + " a cloud may hold");
  // A point is 19 bytes in ROS 1, 20 in CDR (its uint32 aligned): checked before reserving.
  if (static_cast<std::uint64_t>(count) * 19 > data.size())
    Bad(std::string(type) + ": " + std::to_string(count) + " points cannot fit in " +
        std::to_string(data.size()) + " bytes");
  message.declared_points = static_cast<int>(count);
  LidarCloud& cloud = message.cloud;
  cloud.points.reserve(count);
  cloud.intensity.reserve(count);
  message.offset_time_ns.reserve(count);
  std::vector<int> lines;
  lines.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t offset_time = cursor.Read<std::uint32_t>();
    const float x = cursor.Read<float>(), y = cursor.Read<float>(), z = cursor.Read<float>();
    const std::uint8_t reflectivity = cursor.Read<std::uint8_t>();
    const std::uint8_t tag = cursor.Read<std::uint8_t>();
    const std::uint8_t laser = cursor.Read<std::uint8_t>();  // line
    const Eigen::Vector3f point(x, y, z);
    if (!point.allFinite() || point.squaredNorm() < 1e-12f) continue;  // no return
    if ((tag & 0x03) == 0x01) {
      ++message.noise_dropped;
      continue;
    }
    cloud.points.push_back(point);
    cloud.intensity.push_back(reflectivity);
    message.offset_time_ns.push_back(offset_time);
    lines.push_back(laser);
  }
  // Each return at its own time: timebase + offset_time, after the header's stamp.
  const double after_stamp_s =
      (static_cast<double>(message.timebase_ns) - static_cast<double>(message.header.stamp_ns)) *
      1e-9;
  cloud.time_s.reserve(message.offset_time_ns.size());
  for (const std::uint32_t offset : message.offset_time_ns)
    cloud.time_s.push_back(static_cast<float>(after_stamp_s + 1e-9 * offset));
  OrderByLaserLine(lines, &cloud, &message.offset_time_ns);
  cloud.width = static_cast<int>(cloud.size());
  cloud.height = 1;
  return message;
}

bool IsCloudType(const std::string& type) {
  return type == kPointCloud2Type || type == kLivoxCustomMsgType || type == kLivox2CustomMsgType;
}

CloudMessage DecodeCloudMessage(std::span<const std::uint8_t> data, bool livox,
                                MessageEncoding encoding, const LoadLimits& limits) {
  if (livox) {
    LivoxCustomMessage message = DecodeLivoxCustomMsg(data, encoding, limits);
    std::string words =
        "per-point times from 'offset_time' (UINT32), nanoseconds after the "
        "message's timebase: " +
        DescribePointTimes(message.cloud.time_s);
    return {std::move(message.header), std::move(message.cloud), std::move(words)};
  }
  PointCloud2Message message = DecodePointCloud2(data, encoding, limits);
  return {std::move(message.header), std::move(message.cloud), std::move(message.point_times)};
}

}  // namespace calibench
