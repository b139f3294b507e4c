// What the three bag readers share: positional file reads, a bounds-checked little-endian
// cursor, chunk decompression. Errors are IoError naming the file and the byte offset.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/types.h"
#include "core/recording/bag.h"

namespace calibench::bag_internal {

// A regular file opened for positional reads (several readers may share nothing but the path).
class RandomAccessFile {
 public:
  explicit RandomAccessFile(const std::filesystem::path& path);
  ~RandomAccessFile();
  RandomAccessFile(const RandomAccessFile&) = delete;
  RandomAccessFile& operator=(const RandomAccessFile&) = delete;

  std::int64_t Size() const { return size_; }
  // The file's size now (a recording still being written grows); returns it.
  std::int64_t Refresh();
  const std::filesystem::path& Path() const { return path_; }
  // Reads exactly `size` bytes at `offset` into `out` (resized); throws IoError "<file>: truncated
  // at byte N (what)" when the file ends first.
  void ReadAt(std::int64_t offset, std::int64_t size, std::vector<std::uint8_t>* out,
              const char* what) const;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::int64_t size_ = 0;
};

// Throws IoError "<file>: <what>".
[[noreturn]] void Fail(const std::filesystem::path& file, const std::string& what);

// Little-endian reads over a byte span; every read checks the bounds and throws IoError naming
// the file, the record and the offset of the span in the file.
class Cursor {
 public:
  Cursor(std::span<const std::uint8_t> bytes, const std::filesystem::path& file,
         std::int64_t file_offset, const char* record)
      : bytes_(bytes), file_(&file), file_offset_(file_offset), record_(record) {}

  std::size_t Position() const { return position_; }
  std::size_t Remaining() const { return bytes_.size() - position_; }
  bool AtEnd() const { return position_ == bytes_.size(); }

  template <typename T>
  T Read() {
    static_assert(std::is_trivially_copyable_v<T>);
    Need(sizeof(T), "a number");
    T value;
    std::memcpy(&value, bytes_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return value;  // every supported machine is little-endian, as both formats are
  }
  std::span<const std::uint8_t> Bytes(std::uint64_t size, const char* what) {
    Need(size, what);
    auto span = bytes_.subspan(position_, static_cast<std::size_t>(size));
    position_ += static_cast<std::size_t>(size);
    return span;
  }
  std::string_view Text(std::uint64_t size, const char* what) {
    auto span = Bytes(size, what);
    return {reinterpret_cast<const char*>(span.data()), span.size()};
  }
  // A length-prefixed string: MCAP's uint32 + bytes.
  std::string_view PrefixedText(const char* what) { return Text(Read<std::uint32_t>(), what); }
  [[noreturn]] void Fail(const std::string& what) const;

 private:
  void Need(std::uint64_t size, const char* what) const {
    if (size > Remaining())
      Fail(std::string(record_) + " ends inside " + what + " (" + std::to_string(size) +
           " bytes wanted, " + std::to_string(Remaining()) + " left)");
  }
  std::span<const std::uint8_t> bytes_;
  const std::filesystem::path* file_;
  std::int64_t file_offset_;
  const char* record_;
  std::size_t position_ = 0;
};

// Decompresses a whole chunk whose size is known in advance into `out`. `method` is "bz2",
// "lz4" (the LZ4 frame format, ROS 1's roslz4 and MCAP's) or "zstd". Throws IoError naming the
// file and the chunk's offset on corrupt data or a size other than `uncompressed_size`.
void Decompress(const std::string& method, std::span<const std::uint8_t> compressed,
                std::uint64_t uncompressed_size, std::vector<std::uint8_t>* out,
                const std::filesystem::path& file, std::int64_t chunk_offset);

// A chunk or record that claims more than this is refused before allocation. Recorders write
// 768 KiB .. 4 MiB chunks, but a chunk holds at least one whole message: a 4K BGR image is 25 MB,
// the load limit's 5 million points at 48 bytes 240 MB.
inline constexpr std::uint64_t kMaxChunkBytes = 512ull << 20;

// Readers of one file format each (bag_ros1.cpp, bag_mcap.cpp, bag_sqlite.cpp). With `follow`,
// only the file's start is read (a recording still being written): FollowNewMessages reads on.
std::unique_ptr<BagReader> OpenRos1Bag(const std::filesystem::path& path, bool follow = false);
std::unique_ptr<BagReader> OpenMcap(const std::filesystem::path& path, bool follow = false);
std::unique_ptr<BagReader> OpenSqliteBag(const std::filesystem::path& path, bool follow = false);

// BagReader::CutShort's words for a recording without `missing` ("index", "summary") whose record
// at `offset` runs past the file's `size`.
std::string CutShortAt(std::int64_t offset, std::int64_t size, const char* missing);

// "bz2, lz4" for a listing's compressions; "none" when there are none.
std::string JoinWords(const std::set<std::string>& words);

// Adds a topic (or finds the one with the same name and type) and returns its index.
int AddTopic(std::vector<BagTopic>* topics, const std::string& name, const std::string& type,
             const std::string& encoding_name);

}  // namespace calibench::bag_internal
