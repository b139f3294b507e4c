#include "tests/bag_writers.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

namespace calibench::test {
namespace {
namespace fs = std::filesystem;

using Bytes = std::vector<std::uint8_t>;

// Serializes message fields: ROS 1 (packed little-endian) or CDR (4-byte encapsulation header,
// alignment to each primitive's size from the end of that header, either byte order).
class MessageWriter {
 public:
  MessageWriter(MessageEncoding encoding, bool big_endian)
      : cdr_(encoding == MessageEncoding::kCdr), big_endian_(big_endian) {
    if (cdr_) bytes_ = {0, static_cast<std::uint8_t>(big_endian ? 0 : 1), 0, 0};
  }
  template <typename T>
  void Put(T value) {
    if (cdr_)
      while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian_) std::reverse(raw, raw + sizeof(T));
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void String(const std::string& text) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(text.size() + (cdr_ ? 1 : 0)));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
    if (cdr_) bytes_.push_back(0);
  }
  void ByteSequence(const std::uint8_t* data, std::size_t size) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(size));
    bytes_.insert(bytes_.end(), data, data + size);
  }
  void Header(std::int64_t stamp_ns, const std::string& frame) {
    if (!cdr_) Put<std::uint32_t>(7);  // seq
    Put<std::uint32_t>(static_cast<std::uint32_t>(stamp_ns / 1'000'000'000));
    Put<std::uint32_t>(static_cast<std::uint32_t>(stamp_ns % 1'000'000'000));
    String(frame);
  }
  Bytes Take() { return std::move(bytes_); }

 private:
  bool cdr_;
  bool big_endian_;
  Bytes bytes_;
};

template <typename T>
void PutRaw(Bytes* out, T value, bool big_endian) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian) std::reverse(raw, raw + sizeof(T));
  out->insert(out->end(), raw, raw + sizeof(T));
}

}  // namespace

std::vector<std::uint8_t> SerializeLivoxCustomMsg(const LidarCloud& cloud, std::int64_t stamp_ns,
                                                  const std::string& frame,
                                                  MessageEncoding encoding,
                                                  const std::vector<std::uint32_t>& offsets_ns,
                                                  const std::vector<std::uint8_t>& tags) {
  MessageWriter out(encoding, false);
  out.Header(stamp_ns, frame);
  out.Put<std::uint64_t>(static_cast<std::uint64_t>(stamp_ns));      // timebase
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(cloud.size()));  // point_num
  out.Put<std::uint8_t>(3);                                          // lidar_id
  for (int k = 0; k < 3; ++k) out.Put<std::uint8_t>(0);              // rsvd
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(cloud.size()));  // the sequence's length
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out.Put<std::uint32_t>(offsets_ns.empty() ? static_cast<std::uint32_t>(i * 10'000)
                                              : offsets_ns[i]);
    for (int axis = 0; axis < 3; ++axis) out.Put<float>(cloud.points[i][axis]);
    out.Put<std::uint8_t>(
        cloud.HasIntensity() ? static_cast<std::uint8_t>(std::clamp(cloud.intensity[i], 0.f, 255.f))
                             : 0);
    out.Put<std::uint8_t>(tags.empty() ? 0 : tags[i]);                                      // tag
    out.Put<std::uint8_t>(cloud.HasRing() ? static_cast<std::uint8_t>(cloud.ring[i]) : 0);  // line
  }
  return out.Take();
}

std::vector<std::uint8_t> SerializePointCloud2(const LidarCloud& cloud, std::int64_t stamp_ns,
                                               const std::string& frame, MessageEncoding encoding,
                                               bool big_endian, const char* ring_field,
                                               PointLayout layout) {
  MessageWriter out(encoding, big_endian);
  out.Header(stamp_ns, frame);
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(cloud.height));
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(cloud.width));
  struct Field {
    const char* name;
    std::uint32_t offset;
    std::uint8_t type;  // sensor_msgs/PointField: 4 UINT16, 6 UINT32, 7 FLOAT32
  };
  const bool ouster = layout == PointLayout::kOuster;
  CALIBENCH_CHECK(!ouster || !cloud.HasViewpoint());
  std::vector<Field> fields = {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}};
  if (cloud.HasIntensity()) fields.push_back({"intensity", 16, 7});
  if (ouster) {
    if (cloud.HasTime()) fields.push_back({"t", 20, 6});
    fields.push_back({"reflectivity", 24, 4});
    if (cloud.HasRing()) fields.push_back({"ring", 26, 4});
    fields.push_back({"ambient", 28, 4});
    fields.push_back({"range", 32, 6});
  } else {
    if (cloud.HasRing()) fields.push_back({ring_field, 20, 4});
    if (cloud.HasTime()) fields.push_back({"time", 24, 7});  // velodyne_pointcloud's XYZIRT
    if (cloud.HasViewpoint())                                // PCL's PointWithViewpoint names
      for (const auto& [name, offset] : {std::pair{"vp_x", 32u}, {"vp_y", 36u}, {"vp_z", 40u}})
        fields.push_back({name, offset, 7});
  }
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(fields.size()));
  for (const Field& field : fields) {
    out.String(field.name);
    out.Put<std::uint32_t>(field.offset);
    out.Put<std::uint8_t>(field.type);
    out.Put<std::uint32_t>(1);
  }
  out.Put<std::uint8_t>(big_endian ? 1 : 0);
  const std::uint32_t kStep = ouster || cloud.HasViewpoint() ? 48 : 32;
  out.Put<std::uint32_t>(kStep);
  out.Put<std::uint32_t>(kStep * static_cast<std::uint32_t>(cloud.width));
  Bytes points;
  points.reserve(cloud.size() * kStep);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::size_t start = points.size();
    for (int axis = 0; axis < 3; ++axis) PutRaw<float>(&points, cloud.points[i][axis], big_endian);
    PutRaw<float>(&points, 0.0f, big_endian);  // padding, as PCL's PointXYZ has
    if (cloud.HasIntensity()) PutRaw<float>(&points, cloud.intensity[i], big_endian);
    points.resize(start + 20, 0);
    if (ouster) {
      const std::uint32_t t_ns =
          cloud.HasTime() ? static_cast<std::uint32_t>(std::llround(cloud.time_s[i] * 1e9)) : 0;
      PutRaw<std::uint32_t>(&points, t_ns, big_endian);
      PutRaw<std::uint16_t>(&points, 0, big_endian);  // reflectivity
      PutRaw<std::uint16_t>(
          &points, cloud.HasRing() ? static_cast<std::uint16_t>(cloud.ring[i]) : 0, big_endian);
      PutRaw<std::uint16_t>(&points, 0, big_endian);  // ambient
      points.resize(start + 32, 0);
      PutRaw<std::uint32_t>(&points,
                            static_cast<std::uint32_t>(std::llround(cloud.points[i].norm() * 1e3)),
                            big_endian);  // range (mm)
    } else {
      if (cloud.HasRing())
        PutRaw<std::uint16_t>(&points, static_cast<std::uint16_t>(cloud.ring[i]), big_endian);
      if (cloud.HasTime()) {
        points.resize(start + 24, 0);
        PutRaw<float>(&points, cloud.time_s[i], big_endian);
      }
      if (cloud.HasViewpoint()) {
        points.resize(start + 32, 0);
        for (int axis = 0; axis < 3; ++axis)
          PutRaw<float>(&points, cloud.viewpoint[i][axis], big_endian);
      }
    }
    points.resize(start + kStep, 0);
  }
  out.ByteSequence(points.data(), points.size());
  out.Put<std::uint8_t>(1);  // is_dense
  return out.Take();
}

std::vector<std::uint8_t> SerializeImage(const ImageU8& image, const std::string& encoding,
                                         std::int64_t stamp_ns, const std::string& frame,
                                         MessageEncoding encoding_kind) {
  MessageWriter out(encoding_kind, false);
  out.Header(stamp_ns, frame);
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(image.height));
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(image.width));
  out.String(encoding);
  out.Put<std::uint8_t>(0);
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(image.width * image.channels));
  out.ByteSequence(image.data.data(), image.data.size());
  return out.Take();
}

std::vector<std::uint8_t> SerializeCompressedImage(const std::string& format,
                                                   const std::string& bytes, std::int64_t stamp_ns,
                                                   const std::string& frame,
                                                   MessageEncoding encoding_kind) {
  MessageWriter out(encoding_kind, false);
  out.Header(stamp_ns, frame);
  out.String(format);
  out.ByteSequence(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return out.Take();
}

std::vector<std::uint8_t> SerializeCameraInfo(const CameraModel& camera, std::int64_t stamp_ns,
                                              const std::string& frame,
                                              MessageEncoding encoding_kind) {
  MessageWriter out(encoding_kind, false);
  out.Header(stamp_ns, frame);
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(camera.height));
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(camera.width));
  out.String(camera.type == CameraModelType::kKannalaBrandt ? "equidistant"
             : camera.distortion.size() == 8                ? "rational_polynomial"
                                                            : "plumb_bob");
  out.Put<std::uint32_t>(static_cast<std::uint32_t>(camera.distortion.size()));
  for (const double d : camera.distortion) out.Put<double>(d);
  for (const double k : {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0})
    out.Put<double>(k);
  for (const double r : {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) out.Put<double>(r);
  for (const double p :
       {camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0})
    out.Put<double>(p);
  for (int i = 0; i < 6; ++i) out.Put<std::uint32_t>(0);  // binning x, y; roi x, y, h, w
  out.Put<std::uint8_t>(0);                               // roi.do_rectify
  return out.Take();
}

// ---------------------------------------------------------------------------------------------
namespace {

Bytes Compress(const std::string& method, const Bytes& in) {
  if (method == "none" || method.empty()) return in;
  Bytes out;
  if (method == "bz2") {
    auto size = static_cast<unsigned int>(in.size() + in.size() / 100 + 600);
    out.resize(size);
    if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &size,
                                 const_cast<char*>(reinterpret_cast<const char*>(in.data())),
                                 static_cast<unsigned int>(in.size()), 9, 0, 30) != BZ_OK)
      throw std::runtime_error("bz2 compression failed");
    out.resize(size);
  } else if (method == "lz4") {
    out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
    const std::size_t size =
        LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
    if (LZ4F_isError(size)) throw std::runtime_error("lz4 compression failed");
    out.resize(size);
  } else if (method == "zstd") {
    out.resize(ZSTD_compressBound(in.size()));
    const std::size_t size = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
    if (ZSTD_isError(size)) throw std::runtime_error("zstd compression failed");
    out.resize(size);
  } else {
    throw std::invalid_argument("unknown compression " + method);
  }
  return out;
}

template <typename T>
void Append(Bytes* out, T value) {
  const std::size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &value, sizeof(T));
}
void Append(Bytes* out, const Bytes& bytes) { out->insert(out->end(), bytes.begin(), bytes.end()); }

// ROS 1 record header fields.
struct Field {
  std::string name;
  Bytes value;
};
template <typename T>
Field NumberField(const std::string& name, T value) {
  Bytes bytes;
  Append(&bytes, value);
  return {name, bytes};
}
Field TextField(const std::string& name, const std::string& value) {
  return {name, Bytes(value.begin(), value.end())};
}
Bytes HeaderBytes(const std::vector<Field>& fields) {
  Bytes header;
  for (const Field& field : fields) {
    Append<std::uint32_t>(&header,
                          static_cast<std::uint32_t>(field.name.size() + 1 + field.value.size()));
    header.insert(header.end(), field.name.begin(), field.name.end());
    header.push_back('=');
    Append(&header, field.value);
  }
  return header;
}
void Ros1Record(Bytes* out, const std::vector<Field>& fields, const Bytes& data) {
  const Bytes header = HeaderBytes(fields);
  Append<std::uint32_t>(out, static_cast<std::uint32_t>(header.size()));
  Append(out, header);
  Append<std::uint32_t>(out, static_cast<std::uint32_t>(data.size()));
  Append(out, data);
}
std::uint64_t Ros1Time(std::int64_t ns) {
  return static_cast<std::uint64_t>(ns / 1'000'000'000) |
         (static_cast<std::uint64_t>(ns % 1'000'000'000) << 32);
}

struct Ros1Connection {
  std::uint32_t id;
  std::string topic, type;
};

Bytes ConnectionRecord(const Ros1Connection& connection) {
  Bytes out;
  const Bytes data =
      HeaderBytes({TextField("topic", connection.topic), TextField("type", connection.type),
                   TextField("md5sum", "*"), TextField("message_definition", "")});
  Ros1Record(&out,
             {NumberField<std::uint8_t>("op", 0x07), NumberField("conn", connection.id),
              TextField("topic", connection.topic)},
             data);
  return out;
}

class Ros1BagWriter : public RecordingWriter {
 public:
  Ros1BagWriter(const fs::path& path, std::string compression, std::size_t chunk_bytes)
      : compression_(std::move(compression)), chunk_bytes_(chunk_bytes) {
    file_.open(path, std::ios::binary | std::ios::trunc);
    if (!file_) throw std::runtime_error("cannot write " + path.string());
    Bytes start(std::begin("#ROSBAG V2.0\n"), std::end("#ROSBAG V2.0\n") - 1);
    header_at_ = start.size();
    // As rosbag record does: a bag header with index_pos 0 until the recording is closed.
    Append(&start, BagHeader(0, 0, 0));
    Put(start);
  }
  ~Ros1BagWriter() override {
    if (!closed_) Close();
  }

  void Add(const RecordedMessage& message) override {
    if (chunk_.empty()) info_ = {position_, message.log_time_ns, message.log_time_ns, {}};
    auto [it, added] = connections_.try_emplace(
        message.topic, Ros1Connection{static_cast<std::uint32_t>(connections_.size()),
                                      message.topic, message.type});
    if (defined_.insert(it->second.id).second) Append(&chunk_, ConnectionRecord(it->second));
    index_[it->second.id].emplace_back(message.log_time_ns,
                                       static_cast<std::uint32_t>(chunk_.size()));
    Ros1Record(&chunk_,
               {NumberField<std::uint8_t>("op", 0x02), NumberField("conn", it->second.id),
                NumberField("time", Ros1Time(message.log_time_ns))},
               message.data);
    ++info_.counts[it->second.id];
    info_.start = std::min(info_.start, message.log_time_ns);
    info_.end = std::max(info_.end, message.log_time_ns);
    if (chunk_.size() >= chunk_bytes_) WriteChunk();
  }

  void Close() override {
    if (closed_) return;
    closed_ = true;
    if (!chunk_.empty()) WriteChunk();
    const std::uint64_t index_pos = position_;
    Bytes tail;
    for (const auto& [topic, connection] : connections_)
      Append(&tail, ConnectionRecord(connection));
    for (const ChunkInfo& chunk : chunks_) {
      Bytes data;
      for (const auto& [id, count] : chunk.counts) {
        Append(&data, id);
        Append(&data, count);
      }
      Ros1Record(&tail,
                 {NumberField<std::uint8_t>("op", 0x06), NumberField<std::uint32_t>("ver", 1),
                  NumberField("chunk_pos", chunk.position),
                  NumberField("start_time", Ros1Time(chunk.start)),
                  NumberField("end_time", Ros1Time(chunk.end)),
                  NumberField("count", static_cast<std::uint32_t>(chunk.counts.size()))},
                 data);
    }
    Put(tail);
    file_.seekp(static_cast<std::streamoff>(header_at_));
    const Bytes header = BagHeader(index_pos, connections_.size(), chunks_.size());
    file_.write(reinterpret_cast<const char*>(header.data()),
                static_cast<std::streamsize>(header.size()));
    file_.close();
  }

 private:
  struct ChunkInfo {
    std::uint64_t position = 0;
    std::int64_t start = 0, end = 0;
    std::map<std::uint32_t, std::uint32_t> counts;
  };

  // The bag header record, padded so that the whole record fills 4096 + 200 bytes.
  static Bytes BagHeader(std::uint64_t index_pos, std::size_t connections, std::size_t chunks) {
    Bytes header;
    const std::vector<Field> fields = {
        NumberField<std::uint8_t>("op", 0x03), NumberField("index_pos", index_pos),
        NumberField("conn_count", static_cast<std::uint32_t>(connections)),
        NumberField("chunk_count", static_cast<std::uint32_t>(chunks))};
    const std::size_t reserved = 4096 + 200;
    Ros1Record(&header, fields, Bytes(reserved - 8 - HeaderBytes(fields).size(), ' '));
    return header;
  }

  void Put(const Bytes& bytes) {
    file_.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    file_.flush();
    position_ += bytes.size();
  }

  void WriteChunk() {
    Bytes out;
    Ros1Record(&out,
               {NumberField<std::uint8_t>("op", 0x05), TextField("compression", compression_),
                NumberField("size", static_cast<std::uint32_t>(chunk_.size()))},
               Compress(compression_, chunk_));
    for (const auto& [id, entries] : index_) {
      Bytes data;
      for (const auto& [time, offset] : entries) {
        Append(&data, Ros1Time(time));
        Append(&data, offset);
      }
      Ros1Record(&out,
                 {NumberField<std::uint8_t>("op", 0x04), NumberField<std::uint32_t>("ver", 1),
                  NumberField("conn", id),
                  NumberField("count", static_cast<std::uint32_t>(entries.size()))},
                 data);
    }
    chunks_.push_back(info_);
    Put(out);
    chunk_.clear();
    index_.clear();
    defined_.clear();
  }

  std::ofstream file_;
  std::string compression_;
  std::size_t chunk_bytes_;
  std::size_t header_at_ = 0;
  std::uint64_t position_ = 0;
  bool closed_ = false;
  std::map<std::string, Ros1Connection> connections_;
  std::vector<ChunkInfo> chunks_;
  Bytes chunk_;
  ChunkInfo info_;
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint32_t>>> index_;
  std::set<std::uint32_t> defined_;
};

}  // namespace

std::unique_ptr<RecordingWriter> OpenRos1BagWriter(const fs::path& path,
                                                   const std::string& compression,
                                                   std::size_t chunk_bytes) {
  return std::make_unique<Ros1BagWriter>(path, compression, chunk_bytes);
}

void WriteRos1Bag(const fs::path& path, const std::vector<RecordedMessage>& messages,
                  const std::string& compression, std::size_t chunk_bytes) {
  Ros1BagWriter writer(path, compression, chunk_bytes);
  for (const RecordedMessage& message : messages) writer.Add(message);
  writer.Close();
}

// ---------------------------------------------------------------------------------------------
namespace {

void McapString(Bytes* out, const std::string& text) {
  Append<std::uint32_t>(out, static_cast<std::uint32_t>(text.size()));
  out->insert(out->end(), text.begin(), text.end());
}
void McapRecord(Bytes* out, std::uint8_t op, const Bytes& content) {
  out->push_back(op);
  Append<std::uint64_t>(out, content.size());
  Append(out, content);
}

std::string Ros2Type(const std::string& type) {
  const std::size_t slash = type.find('/');
  return type.substr(0, slash) + "/msg" + type.substr(slash);
}

}  // namespace

namespace {

class McapWriter : public RecordingWriter {
 public:
  McapWriter(const fs::path& path, const std::string& profile, std::string compression,
             bool summary, std::size_t chunk_bytes)
      : ros2_(profile == "ros2"),
        compression_(std::move(compression)),
        summary_(summary),
        chunk_bytes_(chunk_bytes) {
    file_.open(path, std::ios::binary | std::ios::trunc);
    if (!file_) throw std::runtime_error("cannot write " + path.string());
    Bytes start = Magic();
    Bytes header;
    McapString(&header, profile);
    McapString(&header, "calibench test writer");
    McapRecord(&start, 0x01, header);
    Put(start);
  }
  ~McapWriter() override {
    if (!closed_) Close();
  }

  void Add(const RecordedMessage& message) override {
    Define(message);
    if (records_.empty()) first_ = last_ = message.log_time_ns;
    Bytes record;
    Append(&record, channels_[message.topic]);
    Append<std::uint32_t>(&record, static_cast<std::uint32_t>(++sequence_));
    Append<std::uint64_t>(&record, message.log_time_ns);
    Append<std::uint64_t>(&record, message.log_time_ns);
    Append(&record, message.data);
    McapRecord(&records_, 0x05, record);
    ++counts_[channels_[message.topic]];
    first_ = std::min(first_, message.log_time_ns);
    last_ = std::max(last_, message.log_time_ns);
    start_time_ = std::min(start_time_, message.log_time_ns);
    end_time_ = std::max(end_time_, message.log_time_ns);
    ++messages_;
    if (records_.size() >= chunk_bytes_) WriteChunk();
  }

  void Close() override {
    if (closed_) return;
    closed_ = true;
    if (!records_.empty()) WriteChunk();
    Bytes tail;
    McapRecord(&tail, 0x0F, Bytes(4, 0));  // DataEnd, no CRC
    std::uint64_t summary_start = 0;
    if (summary_) {
      summary_start = position_ + tail.size();
      Append(&tail, definitions_);
      Bytes statistics;
      Append<std::uint64_t>(&statistics, messages_);
      Append<std::uint16_t>(&statistics, static_cast<std::uint16_t>(schemas_.size()));
      Append<std::uint32_t>(&statistics, static_cast<std::uint32_t>(channels_.size()));
      Append<std::uint32_t>(&statistics, 0);
      Append<std::uint32_t>(&statistics, 0);
      Append<std::uint32_t>(&statistics, chunk_count_);
      Append<std::uint64_t>(&statistics, messages_ == 0 ? 0 : start_time_);
      Append<std::uint64_t>(&statistics, messages_ == 0 ? 0 : end_time_);
      Append<std::uint32_t>(&statistics, static_cast<std::uint32_t>(counts_.size() * 10));
      for (const auto& [channel, count] : counts_) {
        Append(&statistics, channel);
        Append(&statistics, count);
      }
      McapRecord(&tail, 0x0B, statistics);
    }
    Bytes footer;
    Append<std::uint64_t>(&footer, summary_start);
    Append<std::uint64_t>(&footer, 0);
    Append<std::uint32_t>(&footer, 0);
    McapRecord(&tail, 0x02, footer);
    Append(&tail, Magic());
    Put(tail);
    file_.close();
  }

 private:
  static Bytes Magic() { return {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'}; }

  void Put(const Bytes& bytes) {
    file_.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    file_.flush();
    position_ += bytes.size();
  }

  // Schema and channel records go to the file before the chunk that first uses them, and again
  // into the summary.
  void Define(const RecordedMessage& message) {
    const std::string type = ros2_ ? Ros2Type(message.type) : message.type;
    Bytes definitions;
    if (!schemas_.count(type)) {
      const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
      schemas_[type] = id;
      Bytes schema;
      Append(&schema, id);
      McapString(&schema, type);
      McapString(&schema, ros2_ ? "ros2msg" : "ros1msg");
      McapString(&schema, "");
      McapRecord(&definitions, 0x03, schema);
    }
    if (!channels_.count(message.topic)) {
      const auto id = static_cast<std::uint16_t>(channels_.size());
      channels_[message.topic] = id;
      Bytes channel;
      Append(&channel, id);
      Append(&channel, schemas_[type]);
      McapString(&channel, message.topic);
      McapString(&channel, ros2_ ? "cdr" : "ros1");
      Append<std::uint32_t>(&channel, 0);  // metadata: an empty map
      McapRecord(&definitions, 0x04, channel);
    }
    if (definitions.empty()) return;
    Append(&definitions_, definitions);
    Put(definitions);
  }

  void WriteChunk() {
    Bytes chunk;
    Append<std::uint64_t>(&chunk, first_);
    Append<std::uint64_t>(&chunk, last_);
    Append<std::uint64_t>(&chunk, records_.size());
    Append<std::uint32_t>(&chunk, 0);  // no CRC
    McapString(&chunk, compression_);
    const Bytes stored = Compress(compression_, records_);
    Append<std::uint64_t>(&chunk, stored.size());
    Append(&chunk, stored);
    Bytes out;
    McapRecord(&out, 0x06, chunk);
    Put(out);
    ++chunk_count_;
    records_.clear();
  }

  std::ofstream file_;
  bool ros2_;
  std::string compression_;
  bool summary_;
  std::size_t chunk_bytes_;
  std::uint64_t position_ = 0;
  bool closed_ = false;
  std::map<std::string, std::uint16_t> schemas_, channels_;
  Bytes definitions_;
  std::map<std::uint16_t, std::uint64_t> counts_;
  std::uint32_t chunk_count_ = 0;
  std::uint64_t messages_ = 0, sequence_ = 0;
  Bytes records_;
  std::int64_t first_ = 0, last_ = 0;
  std::int64_t start_time_ = INT64_MAX, end_time_ = INT64_MIN;
};

}  // namespace

std::unique_ptr<RecordingWriter> OpenMcapWriter(const fs::path& path, const std::string& profile,
                                                const std::string& compression, bool summary,
                                                std::size_t chunk_bytes) {
  return std::make_unique<McapWriter>(path, profile, compression, summary, chunk_bytes);
}

void WriteMcap(const fs::path& path, const std::vector<RecordedMessage>& messages,
               const std::string& profile, const std::string& compression, bool summary,
               std::size_t chunk_bytes) {
  McapWriter writer(path, profile, compression, summary, chunk_bytes);
  for (const RecordedMessage& message : messages) writer.Add(message);
  writer.Close();
}

// ---------------------------------------------------------------------------------------------
namespace {

// rosbag2's sqlite3 storage as it records: the tables first, then messages committed in
// transactions of `commit_every` (rosbag2 commits in batches too).
class Db3Writer : public RecordingWriter {
 public:
  Db3Writer(const fs::path& path, int commit_every) : commit_every_(commit_every) {
    fs::remove(path);
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) throw std::runtime_error("sqlite3_open");
    // A reader (watch) may hold a shared lock for a moment: wait for it, as a recorder should.
    sqlite3_busy_timeout(db_, 5000);
    // rosbag2_storage_default_plugins' schema (Humble).
    Exec(
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);"
        "INSERT INTO schema VALUES(3,'humble');"
        "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,"
        "metadata TEXT NOT NULL);"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
        "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
        "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "BEGIN;");
    sqlite3_prepare_v2(db_, "INSERT INTO topics VALUES(?,?,?,'cdr','')", -1, &topic_, nullptr);
    sqlite3_prepare_v2(db_, "INSERT INTO messages(topic_id,timestamp,data) VALUES(?,?,?)", -1,
                       &message_, nullptr);
  }
  ~Db3Writer() override {
    if (db_) Close();
  }

  void Add(const RecordedMessage& m) override {
    if (!topics_.count(m.topic)) {
      const int id = static_cast<int>(topics_.size()) + 1;
      topics_[m.topic] = id;
      const std::string type = Ros2Type(m.type);
      sqlite3_bind_int(topic_, 1, id);
      sqlite3_bind_text(topic_, 2, m.topic.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_text(topic_, 3, type.c_str(), -1, SQLITE_TRANSIENT);
      if (sqlite3_step(topic_) != SQLITE_DONE) throw std::runtime_error("insert topic");
      sqlite3_reset(topic_);
    }
    sqlite3_bind_int(message_, 1, topics_[m.topic]);
    sqlite3_bind_int64(message_, 2, m.log_time_ns);
    sqlite3_bind_blob(message_, 3, m.data.data(), static_cast<int>(m.data.size()), SQLITE_STATIC);
    if (sqlite3_step(message_) != SQLITE_DONE) throw std::runtime_error("insert message");
    sqlite3_reset(message_);
    if (++uncommitted_ >= commit_every_) {
      Exec("COMMIT; BEGIN;");
      uncommitted_ = 0;
    }
  }

  void Close() override {
    if (!db_) return;
    sqlite3_finalize(topic_);
    sqlite3_finalize(message_);
    Exec("COMMIT;");
    sqlite3_close(db_);
    db_ = nullptr;
  }

 private:
  void Exec(const char* sql) {
    if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK)
      throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db_));
  }

  sqlite3* db_ = nullptr;
  sqlite3_stmt* topic_ = nullptr;
  sqlite3_stmt* message_ = nullptr;
  std::map<std::string, int> topics_;
  int commit_every_;
  int uncommitted_ = 0;
};

}  // namespace

std::unique_ptr<RecordingWriter> OpenDb3Writer(const fs::path& path, int commit_every) {
  return std::make_unique<Db3Writer>(path, commit_every);
}

void WriteDb3(const fs::path& path, const std::vector<RecordedMessage>& messages) {
  Db3Writer writer(path, static_cast<int>(messages.size()) + 1);
  for (const RecordedMessage& message : messages) writer.Add(message);
  writer.Close();
}

}  // namespace calibench::test
