// Reading ROS messages field by field (core/recording/ros_messages.cpp, ros_image_messages.cpp):
// the cursor over one message's bytes in either serialization, its header, and the row checks of
// PointCloud2 and Image. Internal to calibench_io.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>

#include "core/recording/ros_messages.h"

namespace calibench::ros_detail {

[[noreturn]] inline void Bad(const std::string& what) { throw std::invalid_argument(what); }

// A message's rows (PointCloud2, Image): the declared stride holds a row of row_bytes, and the
// data holds stride x height bytes. Both products of uint32 fit in 64 unsigned bits.
inline void CheckRows(const char* type, const char* stride_name, std::uint32_t stride,
                      const char* row_name, std::uint64_t row_bytes, std::uint32_t height,
                      std::size_t data_bytes) {
  if (stride < row_bytes)
    Bad(std::string(type) + ": " + stride_name + " " + std::to_string(stride) +
        " is shorter than " + row_name + " = " + std::to_string(row_bytes) + " bytes");
  if (static_cast<std::uint64_t>(stride) * height > data_bytes)
    Bad(std::string(type) + ": " + std::to_string(data_bytes) + " bytes of data for " +
        stride_name + " x height = " + std::to_string(static_cast<std::uint64_t>(stride) * height));
}

template <typename T>
T ByteSwapped(T value) {
  std::uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// Reads one message's fields in order. ROS 1: little-endian, packed. CDR: a 4-byte
// encapsulation header giving the byte order, then every primitive aligned to its size counted
// from the end of that header (OMG CDR as ROS 2's rmw implementations write it).
class MessageCursor {
 public:
  MessageCursor(std::span<const std::uint8_t> data, MessageEncoding encoding, const char* type)
      : data_(data), type_(type) {
    if (encoding == MessageEncoding::kCdr) {
      cdr_ = true;
      if (data.size() < 4) Bad(std::string(type) + ": shorter than the CDR header");
      // 0x0000 CDR big-endian, 0x0001 CDR little-endian; ROS 2 writes plain CDR only.
      if (data[0] != 0 || data[1] > 1)
        Bad(std::string(type) + ": CDR encapsulation " + std::to_string(data[0] * 256 + data[1]) +
            " (only plain CDR, 0 and 1, is what ROS 2 records)");
      big_endian_ = data[1] == 0;
      origin_ = position_ = 4;
    } else if (encoding != MessageEncoding::kRos1) {
      Bad(std::string(type) + ": neither ROS 1 nor CDR serialization");
    }
  }

  template <typename T>
  T Read() {
    Align(sizeof(T));
    Need(sizeof(T), "a number");
    T value;
    std::memcpy(&value, data_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return big_endian_ ? ByteSwapped(value) : value;
  }
  std::string String(const char* what) {
    const std::uint32_t length = Read<std::uint32_t>();
    Need(length, what);
    const char* text = reinterpret_cast<const char*>(data_.data() + position_);
    position_ += length;
    std::size_t size = length;
    if (cdr_ && size > 0 && text[size - 1] == '\0') --size;  // CDR counts the terminator
    return std::string(text, size);
  }
  std::span<const std::uint8_t> ByteSequence(const char* what) {
    const std::uint32_t length = Read<std::uint32_t>();
    Need(length, what);
    auto bytes = data_.subspan(position_, length);
    position_ += length;
    return bytes;
  }
  void ReadDoubles(double* out, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) out[i] = Read<double>();
  }

 private:
  void Align(std::size_t size) {
    if (!cdr_) return;
    const std::size_t from_origin = position_ - origin_;
    position_ = origin_ + (from_origin + size - 1) / size * size;
  }
  void Need(std::uint64_t size, const char* what) const {
    if (position_ > data_.size() || size > data_.size() - position_)
      Bad(std::string(type_) + ": the message ends inside " + what + " (byte " +
          std::to_string(position_) + " of " + std::to_string(data_.size()) + ")");
  }

  std::span<const std::uint8_t> data_;
  const char* type_;
  bool cdr_ = false;
  bool big_endian_ = false;
  std::size_t origin_ = 0;
  std::size_t position_ = 0;
};

inline RosHeader ReadHeader(MessageCursor& cursor, MessageEncoding encoding) {
  RosHeader header;
  if (encoding == MessageEncoding::kRos1) cursor.Read<std::uint32_t>();  // seq, gone in ROS 2
  const std::int64_t seconds = encoding == MessageEncoding::kRos1 ? cursor.Read<std::uint32_t>()
                                                                  : cursor.Read<std::int32_t>();
  const std::uint32_t nanoseconds = cursor.Read<std::uint32_t>();
  header.stamp_ns = seconds * 1'000'000'000 + nanoseconds;
  header.frame_id = cursor.String("the frame id");
  return header;
}

}  // namespace calibench::ros_detail
