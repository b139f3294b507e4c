// MCAP (https://mcap.dev/spec), read without a library: Debian packages no C++ MCAP reader.
//
// The file: magic, a Header record, the data section (Schema, Channel and Message records, most
// often inside Chunk records, compressed with zstd or lz4 or not at all), DataEnd, an optional
// summary section (Schema, Channel, Statistics, ChunkIndex, ...), a Footer pointing at the
// summary, magic. Every record is <u8 opcode><u64 length><content>; strings are <u32 length>
// <bytes>. Topics and counts come from the summary when it has Statistics, else from one pass.
#include <map>
#include <set>

#include "core/recording/bag_internal.h"

namespace calibench::bag_internal {
namespace {
namespace fs = std::filesystem;

constexpr std::string_view kMcapMagic("\x89MCAP0\r\n", 8);
constexpr std::uint8_t kMcapOpHeader = 0x01;
constexpr std::uint8_t kMcapOpFooter = 0x02;
constexpr std::uint8_t kMcapOpSchema = 0x03;
constexpr std::uint8_t kMcapOpChannel = 0x04;
constexpr std::uint8_t kMcapOpMessage = 0x05;
constexpr std::uint8_t kMcapOpChunk = 0x06;
constexpr std::uint8_t kMcapOpChunkIndex = 0x08;
constexpr std::uint8_t kMcapOpStatistics = 0x0B;
constexpr std::uint8_t kMcapOpDataEnd = 0x0F;
constexpr std::int64_t kMcapFooterBytes = 1 + 8 + 8 + 8 + 4;

class Mcap final : public BagReader {
 public:
  Mcap(const fs::path& path, bool follow) : file_(path) {
    path_ = path;
    size_bytes_ = file_.Size();
    std::vector<std::uint8_t> bytes;
    file_.ReadAt(0, 8, &bytes, "the magic");
    if (std::string_view(reinterpret_cast<const char*>(bytes.data()), 8) != kMcapMagic)
      Fail(path, "an MCAP of a version other than 0");
    std::uint8_t op = 0;
    const std::int64_t header_end = ReadRecord(8, &op, &bytes);
    if (op != kMcapOpHeader) Fail(path, "the first record is not the MCAP header");
    Cursor header(bytes, path_, 8, "the header");
    profile_ = std::string(header.PrefixedText("the profile"));
    data_start_ = header_end;
    follow_offset_ = data_start_;
    if (follow) {
      format_ =
          "MCAP (" + (profile_.empty() ? std::string("no") : profile_) + " profile), followed";
      return;
    }
    if (!ReadSummary()) {
      data_end_ = CompleteEnd();
      CountByScanning();
    }
    format_ = "MCAP (" + (profile_.empty() ? std::string("no") : profile_) + " profile), " +
              std::to_string(chunk_count_) + " chunks" +
              (compressions_.empty() ? "" : " (" + JoinWords(compressions_) + ")");
  }

  void ForEachMessage(const std::vector<bool>& wanted, const BagVisitor& visit,
                      const BagProgress& progress) override {
    std::vector<std::uint8_t> content, chunk;
    std::uint8_t op = 0;
    for (std::int64_t offset = data_start_; offset < data_end_;) {
      const std::int64_t next = ReadRecord(offset, &op, &content);
      bool go_on = true;
      if (op == kMcapOpChunk) {
        go_on = VisitChunk(content, offset, &chunk, wanted, visit);
      } else if (op == kMcapOpDataEnd || op == kMcapOpFooter) {
        break;
      } else {
        go_on = VisitRecord(op, content, offset, wanted, visit);
      }
      if (progress) progress(next, size_bytes_);
      if (!go_on) return;
      offset = next;
    }
  }

  bool FollowNewMessages(const BagVisitor& visit_message) override {
    if (closed_) return true;
    const BagVisitor visit = CountingAsVisited(visit_message);
    size_bytes_ = file_.Refresh();
    std::vector<std::uint8_t> head, content, chunk;
    while (follow_offset_ + 9 <= size_bytes_) {
      file_.ReadAt(follow_offset_, 9, &head, "a record's opcode and length");
      const std::uint8_t op = head[0];
      std::uint64_t length;
      std::memcpy(&length, head.data() + 1, 8);
      if (length > kMaxChunkBytes)
        Fail(path_, "the record at byte " + std::to_string(follow_offset_) + " declares " +
                        std::to_string(length) + " bytes, over the limit");
      const std::int64_t next = follow_offset_ + 9 + static_cast<std::int64_t>(length);
      if (next > size_bytes_) break;  // still being written
      if (op == kMcapOpDataEnd || op == kMcapOpFooter) {
        closed_ = true;
        return true;
      }
      file_.ReadAt(follow_offset_ + 9, static_cast<std::int64_t>(length), &content, "a record");
      if (op == kMcapOpChunk) {
        VisitChunk(content, follow_offset_, &chunk, {}, visit);
      } else {
        VisitRecord(op, content, follow_offset_, {}, visit);
      }
      follow_offset_ = next;
    }
    return false;
  }

 private:
  // Reads the record at `offset`: its opcode and content. Returns where the next one starts.
  std::int64_t ReadRecord(std::int64_t offset, std::uint8_t* op,
                          std::vector<std::uint8_t>* content) const {
    std::vector<std::uint8_t> head;
    file_.ReadAt(offset, 9, &head, "a record's opcode and length");
    *op = head[0];
    std::uint64_t length;
    std::memcpy(&length, head.data() + 1, 8);
    if (length > kMaxChunkBytes)
      Fail(path_, "the record at byte " + std::to_string(offset) + " declares " +
                      std::to_string(length) + " bytes, over the limit");
    file_.ReadAt(offset + 9, static_cast<std::int64_t>(length), content, "a record");
    return offset + 9 + static_cast<std::int64_t>(length);
  }

  // The summary's schemas, channels and statistics; false when the file has no usable summary
  // (a recording that was not closed, or one written without statistics).
  bool ReadSummary() {
    if (size_bytes_ < 8 + kMcapFooterBytes + 8) return false;
    const std::int64_t footer_at = size_bytes_ - 8 - kMcapFooterBytes;
    std::vector<std::uint8_t> bytes;
    file_.ReadAt(footer_at, kMcapFooterBytes + 8, &bytes, "the footer");
    if (bytes[0] != kMcapOpFooter ||
        std::string_view(reinterpret_cast<const char*>(bytes.data()) + kMcapFooterBytes, 8) !=
            kMcapMagic)
      return false;
    std::uint64_t summary_start;
    std::memcpy(&summary_start, bytes.data() + 9, 8);
    if (summary_start == 0 || summary_start < static_cast<std::uint64_t>(data_start_) ||
        summary_start >= static_cast<std::uint64_t>(footer_at))
      return false;
    bool statistics = false;
    std::uint8_t op = 0;
    for (std::int64_t offset = static_cast<std::int64_t>(summary_start); offset < footer_at;) {
      const std::int64_t next = ReadRecord(offset, &op, &bytes);
      if (op == kMcapOpStatistics) {
        ReadStatistics(bytes, offset);
        statistics = true;
      } else if (op == kMcapOpChunkIndex) {
        Cursor index(bytes, path_, offset, "a chunk index");
        index.Bytes(8 * 4, "the chunk's times and position");
        index.Bytes(index.Read<std::uint32_t>(), "the message index offsets");
        index.Read<std::uint64_t>();  // message index length
        compressions_.insert(NameOf(std::string(index.PrefixedText("the compression"))));
      } else {
        VisitRecord(op, bytes, offset, {}, {});
      }
      offset = next;
    }
    data_end_ = static_cast<std::int64_t>(summary_start);
    return statistics;
  }

  void ReadStatistics(std::span<const std::uint8_t> content, std::int64_t offset) {
    Cursor stats(content, path_, offset, "the statistics");
    stats.Read<std::uint64_t>();  // messages
    stats.Read<std::uint16_t>();  // schemas
    stats.Read<std::uint32_t>();  // channels
    stats.Read<std::uint32_t>();  // attachments
    stats.Read<std::uint32_t>();  // metadata
    chunk_count_ = stats.Read<std::uint32_t>();
    stats.Read<std::uint64_t>();  // first message time
    stats.Read<std::uint64_t>();  // last message time
    Cursor counts(stats.Bytes(stats.Read<std::uint32_t>(), "the message counts"), path_, offset,
                  "the statistics' message counts");
    while (!counts.AtEnd()) {
      const std::uint16_t channel = counts.Read<std::uint16_t>();
      const std::uint64_t count = counts.Read<std::uint64_t>();
      const auto topic = channel_topic_.find(channel);
      if (topic == channel_topic_.end())
        Fail(path_, "the statistics count messages of channel " + std::to_string(channel) +
                        ", which the summary does not define");
      // A message record takes 31 bytes at least: more than the file can hold is damage.
      std::int64_t& total = topics_[topic->second].message_count;
      if (count > static_cast<std::uint64_t>(size_bytes_ / 31 - total))
        Fail(path_, "the statistics count " + std::to_string(count) + " messages on channel " +
                        std::to_string(channel) + ", more than the file can hold");
      total += static_cast<std::int64_t>(count);
    }
  }

  // Where the data of a recording without a summary ends: the file's end, or the start of a
  // record the file ends inside (a recorder that crashed mid-chunk), said in cut_short_. Reads
  // only the records' opcodes and lengths.
  std::int64_t CompleteEnd() {
    std::vector<std::uint8_t> head;
    std::int64_t offset = data_start_;
    for (;;) {
      if (offset == size_bytes_) return offset;
      if (offset + 9 <= size_bytes_) {
        file_.ReadAt(offset, 9, &head, "a record's opcode and length");
        std::uint64_t length;
        std::memcpy(&length, head.data() + 1, 8);
        if (head[0] == kMcapOpDataEnd || head[0] == kMcapOpFooter) return size_bytes_;
        if (length > kMaxChunkBytes)
          Fail(path_, "the record at byte " + std::to_string(offset) + " declares " +
                          std::to_string(length) + " bytes, over the limit");
        const std::int64_t next = offset + 9 + static_cast<std::int64_t>(length);
        if (next <= size_bytes_) {
          offset = next;
          continue;
        }
      }
      cut_short_ = CutShortAt(offset, size_bytes_, "summary");
      return offset;
    }
  }

  void CountByScanning() {
    counting_ = true;
    chunk_count_ = 0;
    compressions_.clear();
    ForEachMessage({},
                   [&](const BagMessage& message) {
                     ++topics_[message.topic].message_count;
                     return true;
                   },
                   {});
    counting_ = false;
  }

  static std::string NameOf(const std::string& compression) {
    return compression.empty() ? "none" : compression;
  }
  bool VisitChunk(std::span<const std::uint8_t> content, std::int64_t offset,
                  std::vector<std::uint8_t>* buffer, const std::vector<bool>& wanted,
                  const BagVisitor& visit) {
    Cursor chunk(content, path_, offset, "a chunk");
    chunk.Read<std::uint64_t>();  // first message time
    chunk.Read<std::uint64_t>();  // last message time
    const std::uint64_t uncompressed_size = chunk.Read<std::uint64_t>();
    chunk.Read<std::uint32_t>();  // CRC of the uncompressed records (0 = not computed)
    const std::string compression(chunk.PrefixedText("the compression"));
    std::span<const std::uint8_t> records = chunk.Bytes(chunk.Read<std::uint64_t>(), "records");
    if (counting_) {
      compressions_.insert(NameOf(compression));
      ++chunk_count_;
    }
    if (!compression.empty()) {
      Decompress(compression, records, uncompressed_size, buffer, path_, offset);
      records = *buffer;
    }
    Cursor inner(records, path_, offset, "a chunk's records");
    while (!inner.AtEnd()) {
      const std::uint8_t op = inner.Read<std::uint8_t>();
      const auto record = inner.Bytes(inner.Read<std::uint64_t>(), "a record in a chunk");
      if (!VisitRecord(op, record, offset, wanted, visit)) return false;
    }
    return true;
  }

  // Schemas and channels are registered; messages visited; other records skipped.
  bool VisitRecord(std::uint8_t op, std::span<const std::uint8_t> content, std::int64_t offset,
                   const std::vector<bool>& wanted, const BagVisitor& visit) {
    if (op == kMcapOpSchema) {
      Cursor schema(content, path_, offset, "a schema");
      const std::uint16_t id = schema.Read<std::uint16_t>();
      schema_names_[id] = std::string(schema.PrefixedText("the schema name"));
    } else if (op == kMcapOpChannel) {
      Cursor channel(content, path_, offset, "a channel");
      const std::uint16_t id = channel.Read<std::uint16_t>();
      const std::uint16_t schema_id = channel.Read<std::uint16_t>();
      const std::string topic(channel.PrefixedText("the topic"));
      const std::string encoding(channel.PrefixedText("the message encoding"));
      if (channel_topic_.count(id)) return true;
      const auto schema = schema_names_.find(schema_id);
      if (schema_id != 0 && schema == schema_names_.end())
        channel.Fail("channel '" + topic + "' names schema " + std::to_string(schema_id) +
                     ", which comes nowhere before it");
      channel_topic_[id] =
          AddTopic(&topics_, topic, schema_id == 0 ? "" : schema->second, encoding);
    } else if (op == kMcapOpMessage) {
      Cursor message(content, path_, offset, "a message");
      const std::uint16_t channel = message.Read<std::uint16_t>();
      message.Read<std::uint32_t>();  // sequence
      const std::uint64_t log_time = message.Read<std::uint64_t>();
      message.Read<std::uint64_t>();  // publish time
      const auto topic = channel_topic_.find(channel);
      if (topic == channel_topic_.end())
        message.Fail("a message on channel " + std::to_string(channel) +
                     ", which comes nowhere before it");
      if (!visit || (!wanted.empty() && !wanted[topic->second])) return true;
      BagMessage out;
      out.topic = topic->second;
      out.log_time_ns = static_cast<std::int64_t>(log_time);
      out.data = message.Bytes(message.Remaining(), "the message data");
      return visit(out);
    }
    return true;
  }

  RandomAccessFile file_;
  std::string profile_;
  std::int64_t data_start_ = 0;
  std::int64_t data_end_ = 0;
  std::uint32_t chunk_count_ = 0;
  bool counting_ = false;           // the first pass over a file without a summary
  std::int64_t follow_offset_ = 0;  // FollowNewMessages: where the next record starts
  bool closed_ = false;
  std::set<std::string> compressions_;
  std::map<std::uint16_t, std::string> schema_names_;
  std::map<std::uint16_t, int> channel_topic_;
};

}  // namespace

std::unique_ptr<BagReader> OpenMcap(const fs::path& path, bool follow) {
  return std::make_unique<Mcap>(path, follow);
}

}  // namespace calibench::bag_internal
