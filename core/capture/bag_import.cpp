#include "core/capture/bag_import.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>

#include "core/base/atomic_file.h"
#include "core/io/camera_file.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/recording/ros_messages.h"

namespace calibench {
namespace fs = std::filesystem;

namespace {

// A pair written, under its provisional id until the cap is applied.
struct WrittenPair {
  int found = 0;  // its place among the pairs found
  std::int64_t cloud_stamp_ns = 0, image_stamp_ns = 0;
  bool point_times = false;          // its cloud carries per-point times
  std::vector<StampedImage> frames;  // a moving pair's (images/frame_<stamp>.png, shared)
};

std::string PairId(int index) {
  char id[24];
  std::snprintf(id, sizeof(id), "%04d", index);
  return id;
}

class Importer {
 public:
  Importer(const fs::path& bag_path, const fs::path& out_dir, std::optional<BoardSpec> board,
           BagImportOptions options, const ImportProgress& progress)
      : bag_(OpenBag(bag_path)),
        out_dir_(out_dir),
        board_(std::move(board)),
        options_(std::move(options)),
        progress_(progress) {}

  BagImportSummary Run() {
    std::string why;
    if (!options_.Check(&why)) throw IoError(Where() + ": import options: " + why);
    ChooseTopics(*bag_, &options_);
    cloud_topic_ = bag_->FindTopic(options_.cloud_topic);
    image_topic_ = bag_->FindTopic(options_.image_topic);
    info_topic_ = options_.camera ? -1 : bag_->FindTopic(options_.camera_info_topic);
    summary_.format = bag_->Format();
    if (!bag_->CutShort().empty())
      summary_.cut_short = bag_->Path().string() + ": " + bag_->CutShort();
    summary_.cloud_topic = options_.cloud_topic;
    summary_.image_topic = options_.image_topic;
    summary_.camera_source = options_.camera ? "the --camera file" : options_.camera_info_topic;
    ResolveBoard();
    ReadAndWritePairs();
    Cap();
    WriteDataset();
    return summary_;
  }

 private:
  std::string Where() const { return bag_->Path().string(); }

  void ResolveBoard() { board_ = RecordingBoard(bag_->Path(), board_, &summary_.board_source); }

  void ReadAndWritePairs() {
    fs::create_directories(out_dir_ / "clouds");
    fs::create_directories(out_dir_ / "images");
    RecordingPairFinder finder(Where(), ChosenPairTopics(*bag_, options_), board_, options_.camera,
                               options_);
    std::vector<bool> wanted(bag_->Topics().size(), false);
    wanted[cloud_topic_] = wanted[image_topic_] = true;
    if (info_topic_ >= 0) wanted[info_topic_] = true;
    std::int64_t first_ns = INT64_MAX, last_ns = INT64_MIN;
    bag_->ForEachMessage(
        wanted,
        [&](const BagMessage& message) {
          first_ns = std::min(first_ns, message.log_time_ns);
          last_ns = std::max(last_ns, message.log_time_ns);
          if (message.topic == cloud_topic_) {
            finder.AddCloud(message.data, message.log_time_ns);
          } else if (message.topic == image_topic_) {
            finder.AddImage(message.data, message.log_time_ns);
          } else {
            finder.AddCameraInfo(message.data);
          }
          Write(finder.TakePairs());
          return true;
        },
        [&](std::int64_t done, std::int64_t total) {
          if (progress_) progress_("reading", done, total);
        });
    // Readers stop at the last message record (an MCAP's summary is not read): say 100 %.
    if (progress_) progress_("reading", bag_->SizeBytes(), bag_->SizeBytes());
    finder.Finish();
    Write(finder.TakePairs());
    summary_.bytes_read = bag_->SizeBytes();
    if (last_ns > first_ns) summary_.recording_seconds = (last_ns - first_ns) * 1e-9;
    const PairFinderStats stats = finder.Stats();
    summary_.clouds = stats.clouds;
    summary_.images = stats.images;
    summary_.tries = stats.tries;
    summary_.images_searched = stats.images_searched;
    summary_.boards_seen = stats.boards_found;
    summary_.dropped = stats.dropped;
    summary_.kept_without_stillness_check = stats.kept_without_stillness_check;
    camera_ = finder.Camera();
    if (const auto board = finder.Board()) summary_.board = *board;
    if (!board_ && !stats.board_choice.empty()) summary_.board_source = stats.board_choice;
    if (!camera_)
      throw IoError(Where() + ": no usable camera intrinsics on " + options_.camera_info_topic +
                    ": give them with --camera FILE");
  }

  void Write(std::vector<FoundPair> pairs) {
    for (FoundPair& pair : pairs) {
      const int index = static_cast<int>(written_.size());
      const std::string id = PairId(index);
      if (pair.cloud.HasRing())
        rings_ =
            std::max(rings_, *std::max_element(pair.cloud.ring.begin(), pair.cloud.ring.end()) + 1);
      const PairEntry entry = WriteFoundPair(pair, out_dir_, id);
      // Said once: the first pair's reading stands for the recording's LiDAR.
      if (summary_.point_times.empty()) summary_.point_times = pair.point_times;
      written_.push_back(
          {index, pair.cloud_stamp_ns, pair.image_stamp_ns, pair.cloud.HasTime(), entry.images});
    }
  }

  // At most max_pairs, spread evenly over the recording; the files of the others are removed and
  // the kept ones renumbered from 0000 (ids only ever move down, so no rename overwrites a kept
  // pair's file).
  void Cap() {
    const auto cap = static_cast<std::size_t>(options_.max_pairs);
    if (cap == 0 || written_.size() <= cap) return;
    std::vector<WrittenPair> spread;
    std::vector<bool> keep(written_.size(), false);
    for (std::size_t i = 0; i < cap; ++i)
      keep[cap == 1 ? 0 : i * (written_.size() - 1) / (cap - 1)] = true;
    std::set<fs::path> kept_frames;  // a moving pair's frames may be another's too
    for (std::size_t i = 0; i < written_.size(); ++i)
      if (keep[i])
        for (const StampedImage& frame : written_[i].frames) kept_frames.insert(frame.image);
    for (std::size_t i = 0; i < written_.size(); ++i) {
      const std::string id = PairId(written_[i].found);
      if (keep[i]) {
        spread.push_back(written_[i]);
        continue;
      }
      fs::remove(out_dir_ / "clouds" / (id + ".pcd"));
      fs::remove(out_dir_ / "images" / (id + ".png"));
      for (const StampedImage& frame : written_[i].frames)
        if (!kept_frames.count(frame.image)) fs::remove(frame.image);
      ++summary_.dropped["over the cap of " + std::to_string(cap) + " pairs"];
    }
    for (std::size_t i = 0; i < spread.size(); ++i) {
      const std::string from = PairId(spread[i].found), to = PairId(static_cast<int>(i));
      if (from == to) continue;
      fs::rename(out_dir_ / "clouds" / (from + ".pcd"), out_dir_ / "clouds" / (to + ".pcd"));
      if (spread[i].frames.empty())
        fs::rename(out_dir_ / "images" / (from + ".png"), out_dir_ / "images" / (to + ".png"));
      spread[i].found = static_cast<int>(i);
    }
    written_ = std::move(spread);
  }

  void WriteDataset() {
    if (written_.empty())
      throw IoError(Where() + ": no pair survived the selection (" + DroppedText() + ")");
    SaveCameraInfoYaml(out_dir_ / "camera.yaml", *camera_, "camera");
    Dataset dataset;
    dataset.camera = *camera_;
    dataset.target = summary_.board;
    dataset.lidar_rings = rings_;
    nlohmann::json pairs = nlohmann::json::array();
    for (const WrittenPair& pair : written_) {
      const std::string id = PairId(pair.found);
      PairEntry entry;
      entry.id = id;
      entry.cloud = fs::absolute(out_dir_ / "clouds" / (id + ".pcd"));
      entry.image = fs::absolute(out_dir_ / "images" / (id + ".png"));
      entry.lidar_stamp_ns = pair.cloud_stamp_ns;
      entry.images = pair.frames;
      for (const StampedImage& frame : pair.frames)
        if (frame.stamp_ns == pair.image_stamp_ns) entry.image = frame.image;
      dataset.pairs.push_back(entry);
      summary_.pairs_with_point_times += pair.point_times;
      summary_.moving_pairs += !pair.frames.empty();
      summary_.pair_ids.push_back(id);
      summary_.pair_cloud_stamps_ns.push_back(pair.cloud_stamp_ns);
      pairs.push_back({{"id", id},
                       {"cloud_stamp_ns", pair.cloud_stamp_ns},
                       {"image_stamp_ns", pair.image_stamp_ns}});
      if (!pair.frames.empty()) pairs.back()["frames"] = pair.frames.size();
    }
    summary_.manifest = out_dir_ / "dataset.json";
    SaveDataset(summary_.manifest, dataset);
    nlohmann::json record = {
        {"format", "calibench.import.v1"},     {"source", fs::absolute(bag_->Path()).string()},
        {"source_format", summary_.format},    {"cloud_topic", summary_.cloud_topic},
        {"image_topic", summary_.image_topic}, {"camera", summary_.camera_source},
        {"clouds", summary_.clouds},           {"images", summary_.images},
        {"dropped", summary_.dropped},         {"pairs", pairs}};
    record["kept_without_stillness_check"] = summary_.kept_without_stillness_check;
    record["board"] = summary_.board_source;
    record["tries"] = summary_.tries;
    record["images_searched"] = summary_.images_searched;
    record["point_times"] = summary_.point_times;
    record["moving_pairs"] = summary_.moving_pairs;
    if (!summary_.cut_short.empty()) record["cut_short"] = summary_.cut_short;
    WriteFileAtomically(out_dir_ / "import.json", record.dump(2) + "\n");
  }

  std::string DroppedText() const {
    std::string text;
    for (const auto& [reason, count] : summary_.dropped)
      text += (text.empty() ? "" : "; ") + std::to_string(count) + " " + reason;
    return text.empty() ? "no cloud on the topic" : text;
  }

  std::unique_ptr<BagReader> bag_;
  fs::path out_dir_;
  std::optional<BoardSpec> board_;
  BagImportOptions options_;
  ImportProgress progress_;
  int cloud_topic_ = -1, image_topic_ = -1, info_topic_ = -1;
  int rings_ = 0;
  std::optional<CameraModel> camera_;
  std::vector<WrittenPair> written_;
  BagImportSummary summary_;
};

}  // namespace

std::optional<BoardSpec> RecordingBoard(const fs::path& bag, const std::optional<BoardSpec>& given,
                                        std::string* source) {
  source->clear();
  if (given) {
    *source = "--board";
    return given;
  }
  if (const auto beside = TargetBesideRecording(bag)) {
    *source = beside->string() + " (beside the recording)";
    return LoadTargetFile(*beside);
  }
  return std::nullopt;
}

bool PairTopicsPresent(const BagReader& bag, bool camera_given) {
  auto has = [&](auto is) {
    for (const BagTopic& topic : bag.Topics())
      if (is(topic.type) && topic.message_count > 0) return true;
    return false;
  };
  return has(IsCloudType) &&
         has([](const std::string& t) { return t == kImageType || t == kCompressedImageType; }) &&
         (camera_given || has([](const std::string& t) { return t == kCameraInfoType; }));
}

PairTopics ChosenPairTopics(const BagReader& bag, const BagImportOptions& options) {
  const BagTopic& image = bag.Topics()[bag.FindTopic(options.image_topic)];
  PairTopics topics;
  const BagTopic& cloud = bag.Topics()[bag.FindTopic(options.cloud_topic)];
  topics.cloud = cloud.encoding;
  topics.livox_cloud = cloud.type != kPointCloud2Type;
  topics.image = image.encoding;
  topics.compressed_image = image.type == kCompressedImageType;
  topics.image_topic = options.image_topic;
  if (!options.camera && bag.FindTopic(options.camera_info_topic) >= 0)
    topics.camera_info = bag.Topics()[bag.FindTopic(options.camera_info_topic)].encoding;
  topics.camera_info_topic = options.camera_info_topic;
  return topics;
}

PairEntry WriteFoundPair(const FoundPair& pair, const fs::path& dir, const std::string& id) {
  fs::create_directories(dir / "clouds");
  fs::create_directories(dir / "images");
  PairEntry entry;
  entry.id = id;
  entry.cloud = fs::absolute(dir / "clouds" / (id + ".pcd"));
  entry.lidar_stamp_ns = pair.cloud_stamp_ns;  // what the cloud's field `t` counts from
  SavePcd(entry.cloud, pair.cloud, PcdEncoding::kBinary);
  if (!pair.Moving()) {
    entry.image = fs::absolute(dir / "images" / (id + ".png"));
    SaveImage(entry.image, pair.image);
    return entry;
  }
  // A moving pair's frames, named by stamp: a frame around several sweeps is one file, written
  // by the first pair that holds its pixels.
  for (const FoundFrame& frame : pair.frames) {
    const fs::path path =
        fs::absolute(dir / "images" / ("frame_" + std::to_string(frame.stamp_ns) + ".png"));
    if (!frame.image.empty()) SaveImage(path, frame.image);
    entry.images.push_back({path, frame.stamp_ns});
    if (frame.stamp_ns == pair.image_stamp_ns) entry.image = path;
  }
  return entry;
}

BagImportSummary ImportBag(const fs::path& bag_path, const fs::path& out_dir,
                           const std::optional<BoardSpec>& board, BagImportOptions options,
                           const ImportProgress& progress) {
  return Importer(bag_path, out_dir, board, std::move(options), progress).Run();
}

}  // namespace calibench
