// The sensor_msgs messages Calibench imports, decoded from either serialization: ROS 1's
// (little-endian, packed, strings without a terminator) and ROS 2's CDR (an encapsulation
// header, either byte order, natural alignment, strings with a terminator). The message layouts
// are the same in both generations except std_msgs/Header, which lost its seq in ROS 2.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/camera/camera.h"
#include "core/io/load_limits.h"
#include "core/lidar/cloud.h"
#include "core/recording/bag.h"

namespace calibench {

struct RosHeader {
  std::int64_t stamp_ns = 0;  // the sensor's time of the data
  std::string frame_id;
};

// The std_msgs/Header every stamped message starts with. Throws std::invalid_argument on
// truncated data.
RosHeader DecodeRosHeader(std::span<const std::uint8_t> data, MessageEncoding encoding);

struct PointCloud2Message {
  RosHeader header;
  LidarCloud cloud;         // finite points only; organized when nothing was dropped
  std::string fields;       // "x:FLOAT32@0 y:FLOAT32@4 ..." as the message declares them
  int declared_points = 0;  // width x height
  // How the per-point times were read into cloud.time_s, or why there are none (point_times.h).
  std::string point_times;
};
// Any field layout: x, y, z of any numeric type; intensity from `intensity` (else
// `reflectivity`, `i`); ring from `ring` (else `laser_id`, `channel`, `line`); each return's time
// from the driver's field (core/lidar/point_times.h: `t`, `time`, `timestamp`, ..., Luminar's
// `time_sec` + `time_nsec`), as seconds after header.stamp; either byte order.
// Throws std::invalid_argument naming what is wrong (no x/y/z, fields beyond point_step, data
// shorter than row_step x height, more points than limits.max_cloud_points, ...).
PointCloud2Message DecodePointCloud2(std::span<const std::uint8_t> data, MessageEncoding encoding,
                                     const LoadLimits& limits = {});

struct ImageMessage {
  RosHeader header;
  ImageU8 image;         // 8-bit grey (1 channel) or BGR (3 channels)
  std::string encoding;  // as the message names it ("mono8", "bayer_rggb8", "jpeg", ...)
};
// sensor_msgs/Image: mono8, mono16 (scaled to 8 bits by the image's largest value), rgb8, bgr8,
// rgba8, bgra8, bayer_{rggb,bggr,gbrg,grbg}8 (debayered to BGR), yuv422 / uyvy and yuyv. Throws
// std::invalid_argument for other encodings, a step shorter than a row, short data, or more
// pixels than limits.max_image_pixels.
ImageMessage DecodeImage(std::span<const std::uint8_t> data, MessageEncoding encoding,
                         const LoadLimits& limits = {});
// sensor_msgs/CompressedImage with JPEG or PNG data (decided by the bytes; the format text is
// kept). The pixel count is checked from the header before decoding.
ImageMessage DecodeCompressedImage(std::span<const std::uint8_t> data, MessageEncoding encoding,
                                   const LoadLimits& limits = {});

struct CameraInfoMessage {
  RosHeader header;
  std::string distortion_model;  // as the message names it
  CameraModel camera;
};
// sensor_msgs/CameraInfo -> the camera model (CameraFromCameraInfo in camera_file.h). Throws
// std::invalid_argument for an unknown model, a wrong coefficient count or invalid intrinsics.
CameraInfoMessage DecodeCameraInfo(std::span<const std::uint8_t> data, MessageEncoding encoding);

// livox_ros_driver/CustomMsg and livox_ros_driver2/CustomMsg, the same layout in both drivers:
//   std_msgs/Header header; uint64 timebase; uint32 point_num; uint8 lidar_id; uint8[3] rsvd;
//   CustomPoint[] points  (uint32 offset_time; float32 x, y, z; uint8 reflectivity, tag, line)
// A Livox scanner's returns of one frame in firing order, each with its time after `timebase`.
struct LivoxCustomMessage {
  RosHeader header;
  std::uint64_t timebase_ns = 0;  // the frame's first point
  int lidar_id = 0;
  int declared_points = 0;  // point_num
  // Finite, non-zero returns whose tag does not mark them high-confidence noise (tag bits 0-1 =
  // 01); intensity = reflectivity. No ring: a Livox "line" is a laser of the prism head, whose
  // returns follow the rosette, not a cone. The driver interleaves its lasers (an Avia's 6, a
  // Mid-360's 4); the returns are stored laser by laser, each in firing order, so that
  // consecutive returns are neighbours on one beam's path (board edges from its crossings).
  LidarCloud cloud;                           // time_s: timebase + offset_time after header.stamp
  std::vector<std::uint32_t> offset_time_ns;  // per kept return
  int noise_dropped = 0;                      // returns tagged as noise
};
// Throws std::invalid_argument naming what is wrong (a truncated message, point_num that
// disagrees with the points, more points than limits.max_cloud_points).
LivoxCustomMessage DecodeLivoxCustomMsg(std::span<const std::uint8_t> data,
                                        MessageEncoding encoding, const LoadLimits& limits = {});

// The sensor_msgs types above, by normalized name ("sensor_msgs/Image").
inline constexpr const char* kPointCloud2Type = "sensor_msgs/PointCloud2";
inline constexpr const char* kImageType = "sensor_msgs/Image";
inline constexpr const char* kCompressedImageType = "sensor_msgs/CompressedImage";
inline constexpr const char* kCameraInfoType = "sensor_msgs/CameraInfo";
inline constexpr const char* kLivoxCustomMsgType = "livox_ros_driver/CustomMsg";
inline constexpr const char* kLivox2CustomMsgType = "livox_ros_driver2/CustomMsg";

// The message types a LiDAR's clouds come in: PointCloud2 and the two Livox CustomMsgs.
bool IsCloudType(const std::string& type);

// One LiDAR frame of either type, as a cloud. Throws std::invalid_argument as the decoders do.
struct CloudMessage {
  RosHeader header;
  LidarCloud cloud;
  std::string point_times;  // how cloud.time_s was read, or why it is empty (for a summary)
};
CloudMessage DecodeCloudMessage(std::span<const std::uint8_t> data, bool livox,
                                MessageEncoding encoding, const LoadLimits& limits = {});

}  // namespace calibench
