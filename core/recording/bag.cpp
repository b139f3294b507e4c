// Opening a recording by its first bytes, and what the three readers share.
#include "core/recording/bag.h"

#include <bzlib.h>
#include <fcntl.h>
#include <lz4frame.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>

#include "core/base/names.h"
#include "core/recording/bag_internal.h"

namespace calibench {
namespace fs = std::filesystem;

namespace bag_internal {

void Fail(const fs::path& file, const std::string& what) {
  throw IoError(file.string() + ": " + what);
}

void Cursor::Fail(const std::string& what) const {
  bag_internal::Fail(*file_, what + " (record at byte " + std::to_string(file_offset_) + ")");
}

RandomAccessFile::RandomAccessFile(const fs::path& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) Fail(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat info {};
  if (::fstat(fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    Fail(path, "not a regular file");
  }
  size_ = info.st_size;
}

std::int64_t RandomAccessFile::Refresh() {
  struct stat info {};
  if (::fstat(fd_, &info) == 0) size_ = info.st_size;
  return size_;
}

RandomAccessFile::~RandomAccessFile() {
  if (fd_ >= 0) ::close(fd_);
}

void RandomAccessFile::ReadAt(std::int64_t offset, std::int64_t size,
                              std::vector<std::uint8_t>* out, const char* what) const {
  if (offset < 0 || size < 0 || offset > size_ || size > size_ - offset)
    Fail(path_, std::string("truncated: ") + what + " at byte " + std::to_string(offset) +
                    " needs " + std::to_string(size) + " bytes, the file has " +
                    std::to_string(size_));
  out->resize(static_cast<std::size_t>(size));
  std::int64_t done = 0;
  while (done < size) {
    const ssize_t got =
        ::pread(fd_, out->data() + done, static_cast<std::size_t>(size - done), offset + done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0)
      Fail(path_, std::string("cannot read ") + what + " at byte " + std::to_string(offset) +
                      (got < 0 ? std::string(": ") + std::strerror(errno) : ": unexpected end"));
    done += got;
  }
}

namespace {

void DecompressLz4Frame(std::span<const std::uint8_t> in, std::vector<std::uint8_t>* out,
                        const fs::path& file, const std::string& where) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION)))
    Fail(file, "cannot create an lz4 decoder");
  std::size_t in_done = 0, out_done = 0;
  std::size_t status = 1;
  while (status != 0 && in_done < in.size()) {
    std::size_t out_size = out->size() - out_done;
    std::size_t in_size = in.size() - in_done;
    status = LZ4F_decompress(context, out->data() + out_done, &out_size, in.data() + in_done,
                             &in_size, nullptr);
    if (LZ4F_isError(status)) {
      const std::string name = LZ4F_getErrorName(status);
      LZ4F_freeDecompressionContext(context);
      Fail(file, "corrupt lz4 data in " + where + " (" + name + ")");
    }
    in_done += in_size;
    out_done += out_size;
    if (out_size == 0 && in_size == 0) break;  // output full, more input: wrong declared size
  }
  LZ4F_freeDecompressionContext(context);
  if (out_done != out->size() || status != 0)
    Fail(file, where + ": lz4 data gives " + std::to_string(out_done) + " bytes" +
                   (status != 0 ? " and does not end" : "") + ", the header declares " +
                   std::to_string(out->size()));
}

}  // namespace

void Decompress(const std::string& method, std::span<const std::uint8_t> compressed,
                std::uint64_t uncompressed_size, std::vector<std::uint8_t>* out,
                const fs::path& file, std::int64_t chunk_offset) {
  const std::string where = "the chunk at byte " + std::to_string(chunk_offset);
  if (uncompressed_size > kMaxChunkBytes)
    Fail(file, where + " declares " + std::to_string(uncompressed_size) +
                   " bytes uncompressed, over the limit of " + std::to_string(kMaxChunkBytes));
  out->resize(static_cast<std::size_t>(uncompressed_size));
  if (method == "bz2") {
    auto out_size = static_cast<unsigned int>(uncompressed_size);
    const int status = BZ2_bzBuffToBuffDecompress(
        reinterpret_cast<char*>(out->data()), &out_size,
        const_cast<char*>(reinterpret_cast<const char*>(compressed.data())),
        static_cast<unsigned int>(compressed.size()), 0, 0);
    if (status != BZ_OK || out_size != uncompressed_size)
      Fail(file, "corrupt bz2 data in " + where + " (bzip2 status " + std::to_string(status) +
                     ", " + std::to_string(out_size) + " of " + std::to_string(uncompressed_size) +
                     " bytes)");
  } else if (method == "lz4") {
    DecompressLz4Frame(compressed, out, file, where);
  } else if (method == "zstd") {
    const std::size_t got =
        ZSTD_decompress(out->data(), out->size(), compressed.data(), compressed.size());
    if (ZSTD_isError(got) || got != uncompressed_size)
      Fail(file, "corrupt zstd data in " + where + " (" +
                     (ZSTD_isError(got) ? std::string(ZSTD_getErrorName(got))
                                        : std::to_string(got) + " bytes, " +
                                              std::to_string(uncompressed_size) + " declared") +
                     ")");
  } else {
    Fail(file, where + " uses compression '" + method +
                   "'; Calibench reads uncompressed, bz2, lz4 and zstd chunks");
  }
}

std::string CutShortAt(std::int64_t offset, std::int64_t size, const char* missing) {
  return "cut short at byte " + std::to_string(offset) + " of " + std::to_string(size) + " (no " +
         missing + ", the last record incomplete: its recorder did not close it); read up to there";
}

std::string JoinWords(const std::set<std::string>& words) {
  std::string text;
  for (const std::string& word : words) text += (text.empty() ? "" : ", ") + word;
  return text.empty() ? "none" : text;
}

int AddTopic(std::vector<BagTopic>* topics, const std::string& name, const std::string& type,
             const std::string& encoding_name) {
  const std::string normalized = NormalizeMessageType(type);
  for (std::size_t i = 0; i < topics->size(); ++i)
    if ((*topics)[i].name == name && (*topics)[i].type == normalized) return static_cast<int>(i);
  BagTopic topic;
  topic.name = name;
  topic.type = normalized;
  topic.encoding_name = encoding_name;
  topic.encoding = encoding_name == "ros1"  ? MessageEncoding::kRos1
                   : encoding_name == "cdr" ? MessageEncoding::kCdr
                                            : MessageEncoding::kOther;
  topics->push_back(topic);
  return static_cast<int>(topics->size()) - 1;
}

}  // namespace bag_internal

namespace {

// The recording files of a rosbag2 folder, in natural order.
std::vector<fs::path> FolderBagFiles(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    const std::string extension = entry.path().extension().string();
    if (entry.is_regular_file() && (extension == ".db3" || extension == ".mcap"))
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return NaturalLess(a.filename().string(), b.filename().string());
  });
  return files;
}

// A rosbag2 folder split into several files: their topics merged by name and type, their
// messages one file after the other.
class FolderBag final : public BagReader {
 public:
  FolderBag(const fs::path& folder, std::vector<std::unique_ptr<BagReader>> parts)
      : parts_(std::move(parts)) {
    path_ = folder;
    format_ = "rosbag2 folder of " + std::to_string(parts_.size()) + " files (" +
              parts_.front()->Format() + ")";
    for (const auto& part : parts_) {
      std::vector<int> map;
      for (const BagTopic& topic : part->Topics()) {
        const int index =
            bag_internal::AddTopic(&topics_, topic.name, topic.type, topic.encoding_name);
        topics_[index].message_count += topic.message_count;
        map.push_back(index);
      }
      topic_maps_.push_back(std::move(map));
      size_bytes_ += part->SizeBytes();
      if (!part->CutShort().empty())  // the folder's last file, most often: where it stops
        cut_short_ = part->Path().filename().string() + ": " + part->CutShort();
    }
  }

  void ForEachMessage(const std::vector<bool>& wanted, const BagVisitor& visit,
                      const BagProgress& progress) override {
    std::int64_t done_before = 0;
    bool go_on = true;
    for (std::size_t p = 0; p < parts_.size() && go_on; ++p) {
      const std::vector<int>& map = topic_maps_[p];
      std::vector<bool> part_wanted(map.size(), wanted.empty());
      for (std::size_t t = 0; t < map.size() && !wanted.empty(); ++t)
        part_wanted[t] = wanted[map[t]];
      if (std::find(part_wanted.begin(), part_wanted.end(), true) == part_wanted.end()) {
        done_before += parts_[p]->SizeBytes();
        continue;
      }
      parts_[p]->ForEachMessage(
          part_wanted,
          [&](const BagMessage& message) {
            BagMessage merged = message;
            merged.topic = map[message.topic];
            go_on = visit(merged);
            return go_on;
          },
          [&](std::int64_t done, std::int64_t) {
            if (progress) progress(done_before + done, size_bytes_);
          });
      done_before += parts_[p]->SizeBytes();
    }
  }

 private:
  std::vector<std::unique_ptr<BagReader>> parts_;
  std::vector<std::vector<int>> topic_maps_;
};

std::unique_ptr<BagReader> OpenBagFile(const fs::path& path, bool follow = false) {
  switch (SniffRecording(path)) {
    case RecordingKind::kRos1:
      return bag_internal::OpenRos1Bag(path, follow);
    case RecordingKind::kMcap:
      return bag_internal::OpenMcap(path, follow);
    case RecordingKind::kSqlite:
      return bag_internal::OpenSqliteBag(path, follow);
    case RecordingKind::kNone:
      break;
  }
  bag_internal::Fail(
      path,
      "not a recording Calibench reads (expected a ROS 1 .bag, an .mcap or a rosbag2 .db3; "
      "the file starts with none of their signatures)");
}

// A rosbag2 folder being recorded: its files followed one after the other as they appear (a
// split starts a new one), closed once rosbag2 has written metadata.yaml and every file has
// been read to its end.
class FollowedFolder final : public BagReader {
 public:
  explicit FollowedFolder(const fs::path& folder) {
    path_ = folder;
    format_ = "rosbag2 folder, followed";
  }

  bool FollowNewMessages(const BagVisitor& visit) override {
    std::error_code error;
    // Seen before the files are read: what they hold then is all there will be.
    const bool metadata = fs::exists(path_ / "metadata.yaml", error);
    const std::vector<fs::path> files = FolderBagFiles(path_);
    while (parts_.size() < files.size()) {
      try {
        parts_.push_back(OpenBagFile(files[parts_.size()], true));
      } catch (const IoError&) {
        break;  // a file just begun: the next call
      }
      maps_.emplace_back();
      part_closed_.push_back(false);
    }
    size_bytes_ = 0;
    bool all_closed = parts_.size() == files.size();
    for (std::size_t p = 0; p < parts_.size(); ++p) {
      if (!part_closed_[p])
        part_closed_[p] = parts_[p]->FollowNewMessages([&](const BagMessage& message) {
          std::vector<int>& map = maps_[p];
          const auto& topics = parts_[p]->Topics();
          while (map.size() < topics.size()) {
            const BagTopic& topic = topics[map.size()];
            map.push_back(
                bag_internal::AddTopic(&topics_, topic.name, topic.type, topic.encoding_name));
          }
          ++topics_[map[message.topic]].message_count;
          BagMessage merged = message;
          merged.topic = map[message.topic];
          return visit(merged);
        });
      size_bytes_ += parts_[p]->SizeBytes();
      // A .db3 never says it is closed: metadata.yaml says it for the folder.
      all_closed = all_closed && (part_closed_[p] || metadata);
    }
    return metadata && all_closed && !parts_.empty();
  }

  void ForEachMessage(const std::vector<bool>&, const BagVisitor&, const BagProgress&) override {
    bag_internal::Fail(path_, "a followed recording is read with FollowNewMessages");
  }

 private:
  std::vector<std::unique_ptr<BagReader>> parts_;
  std::vector<std::vector<int>> maps_;  // per part: its topic index -> ours
  std::vector<bool> part_closed_;
};

}  // namespace

BagVisitor BagReader::CountingAsVisited(const BagVisitor& visit) {
  return [this, &visit](const BagMessage& message) {
    ++topics_[message.topic].message_count;
    return visit(message);
  };
}

bool BagReader::FollowNewMessages(const BagVisitor&) {
  bag_internal::Fail(path_, "this reader reads a finished recording only");
}

std::unique_ptr<BagReader> OpenBagToFollow(const fs::path& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return std::make_unique<FollowedFolder>(path);
  if (!fs::exists(path, error)) bag_internal::Fail(path, "no such file or folder (not yet?)");
  return OpenBagFile(path, true);
}

int BagReader::FindTopic(const std::string& name) const {
  for (std::size_t i = 0; i < topics_.size(); ++i)
    if (topics_[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string NormalizeMessageType(const std::string& type) {
  const std::size_t slash = type.find("/msg/");
  if (slash == std::string::npos) return type;
  return type.substr(0, slash) + "/" + type.substr(slash + 5);
}

std::unique_ptr<BagReader> OpenBag(const fs::path& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error || !fs::exists(status)) bag_internal::Fail(path, "no such file or folder");
  if (!fs::is_directory(status)) return OpenBagFile(path);
  const std::vector<fs::path> files = FolderBagFiles(path);
  if (files.empty()) bag_internal::Fail(path, "the folder holds no .db3 or .mcap recording");
  if (files.size() == 1) return OpenBagFile(files.front());
  std::vector<std::unique_ptr<BagReader>> parts;
  for (const fs::path& file : files) parts.push_back(OpenBagFile(file));
  return std::make_unique<FolderBag>(path, std::move(parts));
}

}  // namespace calibench
