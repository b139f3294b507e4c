// Test-side writers of the three recording formats and the sensor_msgs serializations, written
// from the format specifications independently of the readers in core/io (which they test):
// ROS 1 bag 2.0 with uncompressed, bz2 or lz4 chunks and a full index; MCAP with or without a
// summary, chunks uncompressed, zstd or lz4; rosbag2 sqlite3.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/camera/camera.h"
#include "core/lidar/cloud.h"
#include "core/recording/bag.h"

namespace calibench::test {

struct RecordedMessage {
  std::string topic;
  std::string type;  // "sensor_msgs/PointCloud2" (written as sensor_msgs/msg/... for ROS 2)
  std::int64_t log_time_ns = 0;
  std::vector<std::uint8_t> data;  // serialized in the recording's encoding
};

// A driver's point layout.
enum class PointLayout {
  // velodyne_pointcloud's XYZIRT: float32 x y z, intensity float32 at 16, ring uint16 at 20, time
  // float32 (seconds after the stamp) at 24; point_step 32.
  kVelodyne,
  // ouster_ros's PointOS: float32 x y z, intensity float32 at 16, t uint32 (nanoseconds after the
  // stamp) at 20, reflectivity uint16 at 24, ring uint16 at 26, ambient uint16 at 28, range uint32
  // at 32; point_step 48.
  kOuster,
};

// Little-endian, in `layout` (the fields the cloud has; PCL's viewpoint names at 32 for a
// velodyne layout, step 48). With big_endian the same layout in network order (CDR only). A
// velodyne layout's ring field is named `ring_field` ("line": a Livox driver's laser index).
std::vector<std::uint8_t> SerializePointCloud2(const LidarCloud& cloud, std::int64_t stamp_ns,
                                               const std::string& frame, MessageEncoding encoding,
                                               bool big_endian = false,
                                               const char* ring_field = "ring",
                                               PointLayout layout = PointLayout::kVelodyne);
// livox_ros_driver(2)/CustomMsg from its definition: the cloud's points in order, offset_time
// from `offsets_ns` (or 10 µs apart), reflectivity from the intensity, tag 0, line from the
// cloud's ring (the laser; 0 without); `tags` (optional) per point.
std::vector<std::uint8_t> SerializeLivoxCustomMsg(const LidarCloud& cloud, std::int64_t stamp_ns,
                                                  const std::string& frame,
                                                  MessageEncoding encoding,
                                                  const std::vector<std::uint32_t>& offsets_ns = {},
                                                  const std::vector<std::uint8_t>& tags = {});
// `encoding` names the pixel layout of `image` ("bgr8" for 3 channels, "mono8" for 1, or any
// raw layout the caller has already arranged, e.g. "bayer_rggb8").
std::vector<std::uint8_t> SerializeImage(const ImageU8& image, const std::string& encoding,
                                         std::int64_t stamp_ns, const std::string& frame,
                                         MessageEncoding encoding_kind);
std::vector<std::uint8_t> SerializeCompressedImage(const std::string& format,
                                                   const std::string& bytes, std::int64_t stamp_ns,
                                                   const std::string& frame,
                                                   MessageEncoding encoding_kind);
std::vector<std::uint8_t> SerializeCameraInfo(const CameraModel& camera, std::int64_t stamp_ns,
                                              const std::string& frame,
                                              MessageEncoding encoding_kind);

// A recording written message by message, as a recorder does: complete chunks reach the file as
// they fill (flushed), the index or summary only at Close(). Until then the file is what a
// reader sees of a recording still being written.
class RecordingWriter {
 public:
  virtual ~RecordingWriter() = default;
  virtual void Add(const RecordedMessage& message) = 0;
  virtual void Close() = 0;
};
std::unique_ptr<RecordingWriter> OpenRos1BagWriter(const std::filesystem::path& path,
                                                   const std::string& compression,
                                                   std::size_t chunk_bytes = 768 * 1024);
std::unique_ptr<RecordingWriter> OpenMcapWriter(const std::filesystem::path& path,
                                                const std::string& profile,
                                                const std::string& compression, bool summary = true,
                                                std::size_t chunk_bytes = 768 * 1024);

// compression: "none", "bz2" or "lz4". Messages are written in the given order, about
// `chunk_bytes` per chunk.
void WriteRos1Bag(const std::filesystem::path& path, const std::vector<RecordedMessage>& messages,
                  const std::string& compression, std::size_t chunk_bytes = 768 * 1024);
// profile "ros1" (ros1 message encoding) or "ros2" (cdr); compression "", "zstd" or "lz4";
// summary=false leaves the footer without a summary (a reader must then scan).
void WriteMcap(const std::filesystem::path& path, const std::vector<RecordedMessage>& messages,
               const std::string& profile, const std::string& compression, bool summary = true,
               std::size_t chunk_bytes = 768 * 1024);
// The rosbag2 sqlite3 layout written as it records, committing every `commit_every` messages.
std::unique_ptr<RecordingWriter> OpenDb3Writer(const std::filesystem::path& path,
                                               int commit_every = 100);
// The rosbag2 sqlite3 layout (topics + messages tables, CDR data).
void WriteDb3(const std::filesystem::path& path, const std::vector<RecordedMessage>& messages);

}  // namespace calibench::test
