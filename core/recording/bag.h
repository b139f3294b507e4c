// Recordings without ROS: ROS 1 .bag (format 2.0; chunks uncompressed, bz2, lz4), ROS 2 .db3
// (sqlite3) and .mcap (chunks uncompressed, zstd, lz4; profile ros1 or ros2), and a rosbag2
// folder of them. A reader lists the topics and hands out raw serialized messages; decoding the
// sensor_msgs types is ros_messages.h, choosing and pairing them is core/capture/bag_import.h.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/io/recording_kind.h"

namespace calibench {

// How a topic's messages are serialized: ROS 1's (little-endian, packed) or ROS 2's CDR.
enum class MessageEncoding { kRos1, kCdr, kOther };

struct BagTopic {
  std::string name;  // as recorded: "/camera/image_raw" (ROS 1 allows names without a slash)
  // The message type as the file names it, ROS 2's "sensor_msgs/msg/Image" shortened to
  // "sensor_msgs/Image" so that both generations compare equal.
  std::string type;
  MessageEncoding encoding = MessageEncoding::kOther;
  std::string encoding_name;  // as the file says: "ros1", "cdr", "json", ...
  std::int64_t message_count = 0;
};

struct BagMessage {
  int topic = 0;                       // index into BagReader::Topics()
  std::int64_t log_time_ns = 0;        // when the recorder received it (not the header stamp)
  std::span<const std::uint8_t> data;  // valid only during the visit
};

// Bytes of the file read so far and in all, for a progress bar.
using BagProgress = std::function<void(std::int64_t done_bytes, std::int64_t total_bytes)>;
// Returns false to stop reading.
using BagVisitor = std::function<bool(const BagMessage&)>;

class BagReader {
 public:
  virtual ~BagReader() = default;
  const std::filesystem::path& Path() const { return path_; }
  // "ROS 1 bag v2.0, 6 lz4 chunks", "MCAP (ros2 profile), 2 zstd chunks", "rosbag2 sqlite3".
  const std::string& Format() const { return format_; }
  const std::vector<BagTopic>& Topics() const { return topics_; }
  std::int64_t SizeBytes() const { return size_bytes_; }
  // A recording its recorder never closed (a crash, a full disk) may end inside a record: the
  // messages are read up to the last complete one, and this says where the file stops being
  // complete ("cut short at byte N of M: ..."). Empty for a whole recording.
  const std::string& CutShort() const { return cut_short_; }
  // The topic's index by name, -1 when absent.
  int FindTopic(const std::string& name) const;

  // Calls `visit` for every message on the topics with wanted[topic] (all topics when `wanted`
  // is empty), in the order the file stores them (recorders store them by receive time). Throws
  // IoError naming the file on damaged data.
  virtual void ForEachMessage(const std::vector<bool>& wanted, const BagVisitor& visit,
                              const BagProgress& progress = {}) = 0;

  // A recording still being written (a reader from OpenBagToFollow): visits the messages stored
  // since the last call, of every topic, in file order. Only complete records are read; one cut
  // short where the file ends now is read by a later call. Topics() grows as topics appear.
  // Returns true once the recording is closed (its index, summary or metadata written): nothing
  // more will come. Throws IoError naming the file on damaged data.
  virtual bool FollowNewMessages(const BagVisitor& visit);

 protected:
  // `visit` that also counts each message on its topic (a followed recording has no index).
  BagVisitor CountingAsVisited(const BagVisitor& visit);

  std::filesystem::path path_;
  std::string format_;
  std::vector<BagTopic> topics_;
  std::int64_t size_bytes_ = 0;
  std::string cut_short_;
};

// Opens a recording by its content (the first bytes), not its extension; a folder is a rosbag2
// recording (its .db3 and .mcap files in natural order, topics merged). Throws IoError naming the
// file: missing, not a bag, an unsupported version, a damaged index or header.
std::unique_ptr<BagReader> OpenBag(const std::filesystem::path& path);

// A recording that may still be written: a ROS 1 .bag, an .mcap, a rosbag2 .db3 or a rosbag2
// folder of them (closed once its metadata.yaml is written). Throws IoError naming the file when
// it is not there yet or does not start like a recording (a file of a few bytes may be a
// recording just begun: try again).
std::unique_ptr<BagReader> OpenBagToFollow(const std::filesystem::path& path);

// "sensor_msgs/msg/Image" -> "sensor_msgs/Image"; other names unchanged.
std::string NormalizeMessageType(const std::string& type);

}  // namespace calibench
