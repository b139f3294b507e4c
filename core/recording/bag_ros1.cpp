// ROS 1 bag, format 2.0 (http://wiki.ros.org/Bags/Format/2.0), read without ROS.
//
// Our own reader rather than Debian's librosbag-storage: the format is six record kinds, the
// library would bring roscpp_serialization, console_bridge and boost for what this file does in a
// few hundred lines, and its messages would still need decoding by hand here (MCAP files of the
// ros1 profile carry the same serialization, which librosbag-storage cannot read).
//
// A record is <u32 header length><header: fields u32 length + "name=value"><u32 data length>
// <data>. The file: "#ROSBAG V2.0\n", the bag header record (index_pos, conn_count,
// chunk_count), chunks (each holding connection and message records) each followed by index
// records, then at index_pos the connection records and one chunk-info record per chunk.
#include <map>
#include <optional>
#include <set>

#include "core/recording/bag_internal.h"

namespace calibench::bag_internal {
namespace {
namespace fs = std::filesystem;

constexpr std::uint8_t kRos1OpMessage = 0x02;
constexpr std::uint8_t kRos1OpBagHeader = 0x03;
constexpr std::uint8_t kRos1OpChunk = 0x05;
constexpr std::uint8_t kRos1OpChunkInfo = 0x06;
constexpr std::uint8_t kRos1OpConnection = 0x07;
constexpr std::string_view kRos1Magic = "#ROSBAG V2.0\n";

// A record's header fields, viewing the bytes they were parsed from.
class RecordHeader {
 public:
  RecordHeader(std::span<const std::uint8_t> bytes, const fs::path& file, std::int64_t offset)
      : cursor_(bytes, file, offset, "a record header") {
    Cursor cursor = cursor_;
    while (!cursor.AtEnd()) {
      const std::string_view field = cursor.Text(cursor.Read<std::uint32_t>(), "a header field");
      const std::size_t equals = field.find('=');
      if (equals == std::string_view::npos) cursor.Fail("a header field without '='");
      fields_.emplace_back(field.substr(0, equals), field.substr(equals + 1));
    }
  }
  std::optional<std::string_view> Find(std::string_view name) const {
    for (const auto& [key, value] : fields_)
      if (key == name) return value;
    return std::nullopt;
  }
  std::string_view Get(std::string_view name) const {
    const auto value = Find(name);
    if (!value) cursor_.Fail("a record without its '" + std::string(name) + "' field");
    return *value;
  }
  template <typename T>
  T Number(std::string_view name) const {
    const std::string_view value = Get(name);
    if (value.size() != sizeof(T))
      cursor_.Fail("field '" + std::string(name) + "' has " + std::to_string(value.size()) +
                   " bytes, not " + std::to_string(sizeof(T)));
    T number;
    std::memcpy(&number, value.data(), sizeof(T));
    return number;
  }
  std::uint8_t Op() const { return Number<std::uint8_t>("op"); }

 private:
  Cursor cursor_;
  std::vector<std::pair<std::string_view, std::string_view>> fields_;
};

// One record read from the file: its header and data bytes, and where the next one starts.
struct FileRecord {
  std::vector<std::uint8_t> header;
  std::vector<std::uint8_t> data;
  std::int64_t offset = 0;
  std::int64_t next = 0;
};

void ReadRecord(const RandomAccessFile& file, std::int64_t offset, FileRecord* record) {
  std::vector<std::uint8_t> length;
  record->offset = offset;
  file.ReadAt(offset, 4, &length, "a record's header length");
  std::uint32_t header_length;
  std::memcpy(&header_length, length.data(), 4);
  file.ReadAt(offset + 4, header_length, &record->header, "a record header");
  file.ReadAt(offset + 4 + header_length, 4, &length, "a record's data length");
  std::uint32_t data_length;
  std::memcpy(&data_length, length.data(), 4);
  if (data_length > kMaxChunkBytes)
    Fail(file.Path(), "the record at byte " + std::to_string(offset) + " declares " +
                          std::to_string(data_length) + " bytes of data, over the limit");
  file.ReadAt(offset + 8 + header_length, data_length, &record->data, "a record's data");
  record->next = offset + 8 + static_cast<std::int64_t>(header_length) + data_length;
}

class Ros1Bag final : public BagReader {
 public:
  Ros1Bag(const fs::path& path, bool follow) : file_(path) {
    path_ = path;
    size_bytes_ = file_.Size();
    std::vector<std::uint8_t> magic;
    file_.ReadAt(0, static_cast<std::int64_t>(kRos1Magic.size()), &magic, "the format line");
    if (std::string_view(reinterpret_cast<const char*>(magic.data()), magic.size()) != kRos1Magic)
      Fail(path, "a ROS 1 bag of another version than 2.0 (only format 2.0 is read)");
    FileRecord record;
    ReadRecord(file_, static_cast<std::int64_t>(kRos1Magic.size()), &record);
    const RecordHeader header(record.header, path, record.offset);
    if (header.Op() != kRos1OpBagHeader) Fail(path, "the first record is not the bag header");
    data_start_ = record.next;
    follow_offset_ = data_start_;
    if (follow) {
      format_ = "ROS 1 bag v2.0, followed";
      return;
    }
    index_pos_ = static_cast<std::int64_t>(header.Number<std::uint64_t>("index_pos"));
    chunk_count_ = header.Number<std::uint32_t>("chunk_count");
    if (index_pos_ >= data_start_ && index_pos_ < size_bytes_) {
      ReadIndex();
    } else {
      index_pos_ = CompleteEnd();  // not closed by its recorder: no index, count by reading
      CountByScanning();
    }
    format_ = "ROS 1 bag v2.0, " + std::to_string(chunk_count_) + " chunks (" + compression_ + ")" +
              (indexed_ ? "" : ", no index (recording not closed)");
  }

  void ForEachMessage(const std::vector<bool>& wanted, const BagVisitor& visit,
                      const BagProgress& progress) override {
    FileRecord record;
    std::vector<std::uint8_t> chunk;
    for (std::int64_t offset = data_start_; offset < index_pos_; offset = record.next) {
      ReadRecord(file_, offset, &record);
      const RecordHeader header(record.header, path_, offset);
      const std::uint8_t op = header.Op();
      bool go_on = true;
      if (op == kRos1OpChunk) {
        std::span<const std::uint8_t> bytes = record.data;
        const std::string compression(header.Get("compression"));
        if (compression != "none") {
          Decompress(compression, bytes, header.Number<std::uint32_t>("size"), &chunk, path_,
                     offset);
          bytes = chunk;
        }
        go_on = VisitChunk(bytes, offset, wanted, visit);
      } else if (op == kRos1OpMessage) {
        go_on = VisitMessage(header, record.data, wanted, visit);
      } else if (op == kRos1OpConnection) {
        AddConnection(header, record.data, offset);
      }
      if (progress) progress(record.next, size_bytes_);
      if (!go_on) return;
    }
  }

  // rosbag record appends chunks (each followed by its index records) and, when it closes, the
  // connection and chunk-info records of the index: the first of those ends the recording.
  bool FollowNewMessages(const BagVisitor& visit_message) override {
    if (closed_) return true;
    const BagVisitor visit = CountingAsVisited(visit_message);
    size_bytes_ = file_.Refresh();
    std::vector<std::uint8_t> bytes, chunk;
    FileRecord record;
    while (follow_offset_ + 8 <= size_bytes_) {
      file_.ReadAt(follow_offset_, 4, &bytes, "a record's header length");
      std::uint32_t header_length;
      std::memcpy(&header_length, bytes.data(), 4);
      if (follow_offset_ + 8 + header_length > size_bytes_) break;
      file_.ReadAt(follow_offset_ + 4 + header_length, 4, &bytes, "a record's data length");
      std::uint32_t data_length;
      std::memcpy(&data_length, bytes.data(), 4);
      if (follow_offset_ + 8 + static_cast<std::int64_t>(header_length) + data_length > size_bytes_)
        break;  // still being written
      ReadRecord(file_, follow_offset_, &record);
      const RecordHeader header(record.header, path_, follow_offset_);
      const std::uint8_t op = header.Op();
      if (op == kRos1OpConnection || op == kRos1OpChunkInfo) {
        closed_ = true;
        return true;
      }
      if (op == kRos1OpChunk) {
        std::span<const std::uint8_t> data = record.data;
        const std::string compression(header.Get("compression"));
        if (compression != "none") {
          Decompress(compression, data, header.Number<std::uint32_t>("size"), &chunk, path_,
                     follow_offset_);
          data = chunk;
        }
        VisitChunk(data, follow_offset_, {}, visit);
      } else if (op == kRos1OpMessage) {
        VisitMessage(header, record.data, {}, visit);
      }
      follow_offset_ = record.next;
    }
    return false;
  }

 private:
  // Connection and chunk-info records at index_pos: topics and counts without touching a chunk.
  void ReadIndex() {
    FileRecord record;
    std::set<std::string> compressions;
    for (std::int64_t offset = index_pos_; offset < size_bytes_; offset = record.next) {
      ReadRecord(file_, offset, &record);
      const RecordHeader header(record.header, path_, offset);
      if (header.Op() == kRos1OpConnection) {
        AddConnection(header, record.data, offset);
      } else if (header.Op() == kRos1OpChunkInfo) {
        Cursor data(record.data, path_, offset, "a chunk-info record");
        const std::uint32_t connections = header.Number<std::uint32_t>("count");
        for (std::uint32_t i = 0; i < connections; ++i) {
          const std::uint32_t id = data.Read<std::uint32_t>();
          const std::uint32_t count = data.Read<std::uint32_t>();
          counts_[id] += count;
        }
        ReadChunkHeaderOnly(static_cast<std::int64_t>(header.Number<std::uint64_t>("chunk_pos")),
                            &compressions);
      }
    }
    for (const auto& [id, count] : counts_) {
      const auto topic = connection_topic_.find(id);
      if (topic == connection_topic_.end())
        Fail(path_, "the index counts messages of connection " + std::to_string(id) +
                        ", which no connection record defines");
      topics_[topic->second].message_count += count;
    }
    indexed_ = true;
    compression_ = JoinWords(compressions);
  }

  // The chunk's compression, from its header alone (its data is not read).
  void ReadChunkHeaderOnly(std::int64_t offset, std::set<std::string>* compressions) {
    std::vector<std::uint8_t> bytes;
    file_.ReadAt(offset, 4, &bytes, "a chunk's header length");
    std::uint32_t header_length;
    std::memcpy(&header_length, bytes.data(), 4);
    file_.ReadAt(offset + 4, header_length, &bytes, "a chunk header");
    const RecordHeader header(bytes, path_, offset);
    if (header.Op() != kRos1OpChunk)
      Fail(path_, "the index points at byte " + std::to_string(offset) + ", which is no chunk");
    compressions->insert(std::string(header.Get("compression")));
  }

  // Where the records of a bag without an index end: the file's end, or the start of a record the
  // file ends inside (a recorder that crashed mid-chunk), said in cut_short_. Reads only the
  // records' lengths.
  std::int64_t CompleteEnd() {
    std::vector<std::uint8_t> bytes;
    std::int64_t offset = data_start_;
    for (;;) {
      if (offset == size_bytes_) return offset;
      if (offset + 8 <= size_bytes_) {
        file_.ReadAt(offset, 4, &bytes, "a record's header length");
        std::uint32_t header_length;
        std::memcpy(&header_length, bytes.data(), 4);
        if (offset + 8 + static_cast<std::int64_t>(header_length) <= size_bytes_) {
          file_.ReadAt(offset + 4 + header_length, 4, &bytes, "a record's data length");
          std::uint32_t data_length;
          std::memcpy(&data_length, bytes.data(), 4);
          const std::int64_t next = offset + 8 + static_cast<std::int64_t>(header_length) +
                                    static_cast<std::int64_t>(data_length);
          if (next <= size_bytes_) {
            offset = next;
            continue;
          }
        }
      }
      cut_short_ = CutShortAt(offset, size_bytes_, "index");
      return offset;
    }
  }

  void CountByScanning() {
    ForEachMessage({},
                   [&](const BagMessage& message) {
                     ++topics_[message.topic].message_count;
                     return true;
                   },
                   {});
    compression_ = "unindexed";
  }

  void AddConnection(const RecordHeader& header, std::span<const std::uint8_t> data,
                     std::int64_t offset) {
    const std::uint32_t id = header.Number<std::uint32_t>("conn");
    if (connection_topic_.count(id)) return;  // repeated in every chunk that uses it
    const RecordHeader connection(data, path_, offset);
    const std::string topic(header.Get("topic"));
    const std::string type(connection.Get("type"));
    connection_topic_[id] = AddTopic(&topics_, topic, type, "ros1");
  }

  bool VisitChunk(std::span<const std::uint8_t> bytes, std::int64_t chunk_offset,
                  const std::vector<bool>& wanted, const BagVisitor& visit) {
    Cursor cursor(bytes, path_, chunk_offset, "a chunk");
    while (!cursor.AtEnd()) {
      const auto header_bytes = cursor.Bytes(cursor.Read<std::uint32_t>(), "a record header");
      const auto data = cursor.Bytes(cursor.Read<std::uint32_t>(), "a record's data");
      const RecordHeader header(header_bytes, path_, chunk_offset);
      const std::uint8_t op = header.Op();
      if (op == kRos1OpConnection) {
        AddConnection(header, data, chunk_offset);
      } else if (op == kRos1OpMessage && !VisitMessage(header, data, wanted, visit)) {
        return false;
      }
    }
    return true;
  }

  bool VisitMessage(const RecordHeader& header, std::span<const std::uint8_t> data,
                    const std::vector<bool>& wanted, const BagVisitor& visit) {
    const std::uint32_t id = header.Number<std::uint32_t>("conn");
    const auto topic = connection_topic_.find(id);
    if (topic == connection_topic_.end())
      Fail(path_, "a message of connection " + std::to_string(id) +
                      " comes before that connection's record");
    if (!wanted.empty() && !wanted[topic->second]) return true;
    const std::uint64_t time = header.Number<std::uint64_t>("time");  // u32 sec, u32 nsec
    BagMessage message;
    message.topic = topic->second;
    message.log_time_ns = static_cast<std::int64_t>(time & 0xffffffffu) * 1'000'000'000 +
                          static_cast<std::int64_t>(time >> 32);
    message.data = data;
    return visit(message);
  }

  RandomAccessFile file_;
  std::int64_t data_start_ = 0;
  std::int64_t index_pos_ = 0;
  std::uint32_t chunk_count_ = 0;
  bool indexed_ = false;
  std::int64_t follow_offset_ = 0;  // FollowNewMessages: where the next record starts
  bool closed_ = false;
  std::string compression_;
  std::map<std::uint32_t, int> connection_topic_;
  std::map<std::uint32_t, std::int64_t> counts_;
};

}  // namespace

std::unique_ptr<BagReader> OpenRos1Bag(const fs::path& path, bool follow) {
  return std::make_unique<Ros1Bag>(path, follow);
}

}  // namespace calibench::bag_internal
