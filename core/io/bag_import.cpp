#include "core/io/bag_import.h"

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
#include "core/io/ros_messages.h"
#include "core/target/board_camera.h"

namespace calibench {
namespace fs = std::filesystem;

namespace {

struct CloudMoment {
  std::int64_t stamp_ns = 0;
  int index = 0;  // the message's place on its topic
};

struct ImageMoment {
  std::int64_t stamp_ns = 0;
  int index = 0;
  std::optional<BoardDetection> detection;  // until its pose is estimated
  bool board_found = false;
  std::optional<Pose> cam_from_board;
  bool unreadable = false;
};

// A candidate pair, from selection to the files.
struct Candidate {
  CloudMoment cloud;
  const ImageMoment* image = nullptr;
  std::string id;
};

std::int64_t StampOrLogTime(const RosHeader& header, const BagMessage& message) {
  return header.stamp_ns != 0 ? header.stamp_ns : message.log_time_ns;
}

ImageMessage DecodeAnyImage(const BagTopic& topic, const BagMessage& message,
                            const LoadLimits& limits) {
  return topic.type == kImageType ? DecodeImage(message.data, topic.encoding, limits)
                                  : DecodeCompressedImage(message.data, topic.encoding, limits);
}

double RotationDeg(const Pose& a, const Pose& b) {
  const Eigen::AngleAxisd delta(a.rotation().transpose() * b.rotation());
  return delta.angle() * kRadToDeg;
}

double TranslationM(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm();
}

std::string Ms(double seconds) {
  return std::to_string(static_cast<int>(std::lround(seconds * 1000))) + " ms";
}

// Everything pass 1 learns from the recording.
struct FirstPass {
  std::vector<CloudMoment> clouds;
  std::vector<ImageMoment> images;  // by stamp after the pass
  std::optional<CameraModel> camera;
  std::string camera_problem;  // why the CameraInfo could not be used
  std::string image_problem;   // the first image that could not be decoded
};

class Importer {
 public:
  Importer(const fs::path& bag_path, const fs::path& out_dir, const BoardSpec& board,
           BagImportOptions options, const ImportProgress& progress)
      : bag_(OpenBag(bag_path)),
        out_dir_(out_dir),
        board_(board),
        options_(std::move(options)),
        progress_(progress) {}

  BagImportSummary Run() {
    std::string why;
    if (!options_.Check(&why)) throw IoError(bag_->Path().string() + ": import options: " + why);
    ChooseTopics(*bag_, &options_);
    cloud_topic_ = bag_->FindTopic(options_.cloud_topic);
    image_topic_ = bag_->FindTopic(options_.image_topic);
    info_topic_ = options_.camera ? -1 : bag_->FindTopic(options_.camera_info_topic);
    summary_.format = bag_->Format();
    summary_.cloud_topic = options_.cloud_topic;
    summary_.image_topic = options_.image_topic;
    summary_.camera_source = options_.camera ? "the --camera file" : options_.camera_info_topic;
    ReadStampsAndBoards();
    std::vector<Candidate> kept = Select();
    WritePairs(&kept);
    WriteDataset(kept);
    return summary_;
  }

 private:
  std::string Where() const { return bag_->Path().string(); }
  void Drop(const std::string& reason) { ++summary_.dropped[reason]; }

  void ReadStampsAndBoards() {
    std::vector<bool> wanted(bag_->Topics().size(), false);
    wanted[cloud_topic_] = wanted[image_topic_] = true;
    if (info_topic_ >= 0) wanted[info_topic_] = true;
    first_.camera = options_.camera;
    int clouds = 0, images = 0;
    bag_->ForEachMessage(
        wanted,
        [&](const BagMessage& message) {
          const BagTopic& topic = bag_->Topics()[message.topic];
          if (message.topic == cloud_topic_) {
            ReadCloudStamp(topic, message, clouds++);
          } else if (message.topic == image_topic_) {
            ReadImage(topic, message, images++);
          } else if (!first_.camera) {
            ReadCameraInfo(topic, message);
          }
          return true;
        },
        [&](std::int64_t done, std::int64_t total) {
          if (progress_) progress_("reading", done, total);
        });
    summary_.bytes_read += bag_->SizeBytes();
    summary_.clouds = clouds;
    summary_.images = images;
    if (!first_.camera)
      throw IoError(Where() + ": no usable camera intrinsics on " + options_.camera_info_topic +
                    (first_.camera_problem.empty() ? "" : " (" + first_.camera_problem + ")") +
                    ": give them with --camera FILE");
    EstimateBoardPoses();
    std::sort(first_.images.begin(), first_.images.end(),
              [](const ImageMoment& a, const ImageMoment& b) { return a.stamp_ns < b.stamp_ns; });
    std::sort(first_.clouds.begin(), first_.clouds.end(),
              [](const CloudMoment& a, const CloudMoment& b) { return a.stamp_ns < b.stamp_ns; });
  }

  void ReadCloudStamp(const BagTopic& topic, const BagMessage& message, int index) {
    try {
      const RosHeader header = DecodeRosHeader(message.data, topic.encoding);
      first_.clouds.push_back({StampOrLogTime(header, message), index});
    } catch (const std::invalid_argument&) {
      Drop("cloud message unreadable");
    }
  }

  void ReadImage(const BagTopic& topic, const BagMessage& message, int index) {
    ImageMoment moment;
    moment.index = index;
    moment.stamp_ns = message.log_time_ns;
    try {
      const ImageMessage image = DecodeAnyImage(topic, message, options_.limits);
      moment.stamp_ns = StampOrLogTime(image.header, message);
      CheckImageSize(image.image);
      std::string why;
      moment.detection = DetectBoard(image.image, board_, BoardDetectionOptions{}, &why);
      moment.board_found = moment.detection.has_value();
    } catch (const std::invalid_argument& error) {
      moment.unreadable = true;
      if (first_.image_problem.empty()) first_.image_problem = error.what();
    }
    first_.images.push_back(std::move(moment));
  }

  // The first image fixes the size; a camera of another size is a rectified or binned stream,
  // whose CameraInfo does not describe these pixels.
  void CheckImageSize(const ImageU8& image) {
    if (image_width_ == 0) {
      image_width_ = image.width;
      image_height_ = image.height;
    }
    if (first_.camera &&
        (first_.camera->width != image.width || first_.camera->height != image.height))
      throw IoError(Where() + ": the images on " + options_.image_topic + " are " +
                    std::to_string(image.width) + " x " + std::to_string(image.height) +
                    " but the camera intrinsics are for " + std::to_string(first_.camera->width) +
                    " x " + std::to_string(first_.camera->height));
  }

  void ReadCameraInfo(const BagTopic& topic, const BagMessage& message) {
    try {
      first_.camera = DecodeCameraInfo(message.data, topic.encoding).camera;
      if (image_width_ > 0 &&
          (first_.camera->width != image_width_ || first_.camera->height != image_height_))
        throw IoError(Where() + ": the CameraInfo on " + options_.camera_info_topic + " is for " +
                      std::to_string(first_.camera->width) + " x " +
                      std::to_string(first_.camera->height) + " images, but " +
                      options_.image_topic + " has " + std::to_string(image_width_) + " x " +
                      std::to_string(image_height_));
    } catch (const std::invalid_argument& error) {
      first_.camera_problem = error.what();
    }
  }

  void EstimateBoardPoses() {
    for (ImageMoment& image : first_.images) {
      if (!image.detection) continue;
      ++summary_.boards_seen;
      std::string why;
      const auto observation =
          EstimateBoardPose(*first_.camera, *image.detection, PnpOptions{}, &why);
      if (observation) image.cam_from_board = observation->cam_from_board;
      image.detection.reset();  // the corners are not needed any more
    }
  }

  const ImageMoment* NearestImage(std::int64_t stamp) const {
    const auto& images = first_.images;
    auto after = std::lower_bound(
        images.begin(), images.end(), stamp,
        [](const ImageMoment& image, std::int64_t t) { return image.stamp_ns < t; });
    const ImageMoment* best = nullptr;
    if (after != images.end()) best = &*after;
    if (after != images.begin()) {
      const ImageMoment* before = &*std::prev(after);
      if (!best || stamp - before->stamp_ns <= best->stamp_ns - stamp) best = before;
    }
    return best;
  }

  // False when another pose within the window differs from the pair's beyond the thresholds.
  bool BoardStill(const ImageMoment& pair_image, std::int64_t cloud_stamp, bool* judged) const {
    const auto half = static_cast<std::int64_t>(options_.still_window_s * 0.5e9);
    *judged = false;
    const auto& images = first_.images;  // sorted by stamp: only the window is looked at
    auto from = std::lower_bound(
        images.begin(), images.end(), cloud_stamp - half,
        [](const ImageMoment& image, std::int64_t t) { return image.stamp_ns < t; });
    for (auto it = from; it != images.end() && it->stamp_ns <= cloud_stamp + half; ++it) {
      const ImageMoment& image = *it;
      if (&image == &pair_image || !image.cam_from_board) continue;
      *judged = true;
      if (TranslationM(*image.cam_from_board, *pair_image.cam_from_board) >
              options_.still_translation_m ||
          RotationDeg(*image.cam_from_board, *pair_image.cam_from_board) >
              options_.still_rotation_deg)
        return false;
    }
    return true;
  }

  std::vector<Candidate> Select() {
    std::vector<Candidate> candidates;
    const auto max_offset = static_cast<std::int64_t>(options_.max_pair_offset_s * 1e9);
    int unjudged = 0;
    for (const CloudMoment& cloud : first_.clouds) {
      const ImageMoment* image = NearestImage(cloud.stamp_ns);
      if (!image || std::abs(image->stamp_ns - cloud.stamp_ns) > max_offset) {
        Drop("no image within " + Ms(options_.max_pair_offset_s));
      } else if (image->unreadable) {
        Drop("image unreadable");
      } else if (!image->board_found) {
        Drop("board not found in the image");
      } else if (!image->cam_from_board) {
        Drop("board pose failed in the image");
      } else {
        bool judged = false;
        if (!BoardStill(*image, cloud.stamp_ns, &judged)) {
          Drop("board moving (within " + Ms(options_.still_window_s / 2) + ")");
          continue;
        }
        if (!judged) ++unjudged;
        candidates.push_back({cloud, image, ""});
      }
    }
    std::vector<Candidate> kept;
    for (const Candidate& candidate : candidates) {
      const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const Candidate& other) {
        return TranslationM(*other.image->cam_from_board, *candidate.image->cam_from_board) <=
                   options_.duplicate_translation_m &&
               RotationDeg(*other.image->cam_from_board, *candidate.image->cam_from_board) <=
                   options_.duplicate_rotation_deg;
      });
      if (duplicate) {
        Drop("near-duplicate board pose");
      } else {
        kept.push_back(candidate);
      }
    }
    summary_.kept_without_stillness_check = unjudged;
    return Cap(std::move(kept));
  }

  std::vector<Candidate> Cap(std::vector<Candidate> kept) {
    const auto cap = static_cast<std::size_t>(options_.max_pairs);
    if (cap == 0 || kept.size() <= cap) return kept;
    std::vector<Candidate> spread;
    for (std::size_t i = 0; i < cap; ++i) {
      const std::size_t pick = cap == 1 ? 0 : i * (kept.size() - 1) / (cap - 1);
      spread.push_back(kept[pick]);
    }
    for (std::size_t i = 0; i < kept.size() - cap; ++i)
      Drop("over the cap of " + std::to_string(cap) + " pairs");
    return spread;
  }

  void WritePairs(std::vector<Candidate>* kept) {
    fs::create_directories(out_dir_ / "clouds");
    fs::create_directories(out_dir_ / "images");
    std::map<int, Candidate*> by_cloud;
    std::map<int, std::vector<Candidate*>> by_image;
    for (std::size_t i = 0; i < kept->size(); ++i) {
      Candidate& candidate = (*kept)[i];
      char id[24];
      std::snprintf(id, sizeof(id), "%04zu", i);
      candidate.id = id;
      by_cloud[candidate.cloud.index] = &candidate;
      by_image[candidate.image->index].push_back(&candidate);
    }
    std::vector<bool> wanted(bag_->Topics().size(), false);
    wanted[cloud_topic_] = wanted[image_topic_] = true;
    int clouds = 0, images = 0;
    std::set<std::string> failed;
    bag_->ForEachMessage(
        wanted,
        [&](const BagMessage& message) {
          const BagTopic& topic = bag_->Topics()[message.topic];
          if (message.topic == cloud_topic_) {
            const auto found = by_cloud.find(clouds++);
            if (found != by_cloud.end() && !WriteCloud(topic, message, *found->second))
              failed.insert(found->second->id);
          } else {
            const auto found = by_image.find(images++);
            if (found != by_image.end())
              for (Candidate* candidate : found->second)
                if (!WriteImage(topic, message, *candidate)) failed.insert(candidate->id);
          }
          return true;
        },
        [&](std::int64_t done, std::int64_t total) {
          if (progress_) progress_("writing", done, total);
        });
    summary_.bytes_read += bag_->SizeBytes();
    std::erase_if(*kept, [&](const Candidate& c) { return failed.count(c.id) > 0; });
  }

  bool WriteCloud(const BagTopic& topic, const BagMessage& message, const Candidate& candidate) {
    try {
      PointCloud2Message cloud = DecodePointCloud2(message.data, topic.encoding, options_.limits);
      if (cloud.cloud.size() == 0) {
        Drop("cloud has no finite point");
        return false;
      }
      if (cloud.cloud.HasRing())
        rings_ = std::max(rings_,
                          *std::max_element(cloud.cloud.ring.begin(), cloud.cloud.ring.end()) + 1);
      SavePcd(out_dir_ / "clouds" / (candidate.id + ".pcd"), cloud.cloud, PcdEncoding::kBinary);
      return true;
    } catch (const std::invalid_argument&) {
      Drop("cloud message unreadable");
      return false;
    }
  }

  bool WriteImage(const BagTopic& topic, const BagMessage& message, const Candidate& candidate) {
    try {
      const ImageMessage image = DecodeAnyImage(topic, message, options_.limits);
      SaveImage(out_dir_ / "images" / (candidate.id + ".png"), image.image);
      return true;
    } catch (const std::invalid_argument&) {
      Drop("image unreadable");
      return false;
    }
  }

  void WriteDataset(const std::vector<Candidate>& kept) {
    if (kept.empty())
      throw IoError(Where() + ": no pair survived the selection (" + DroppedText() + ")");
    SaveCameraInfoYaml(out_dir_ / "camera.yaml", *first_.camera, "camera");
    Dataset dataset;
    dataset.camera = *first_.camera;
    dataset.target = board_;
    dataset.lidar_rings = rings_;
    nlohmann::json pairs = nlohmann::json::array();
    for (const Candidate& candidate : kept) {
      PairEntry entry;
      entry.id = candidate.id;
      entry.cloud = fs::absolute(out_dir_ / "clouds" / (candidate.id + ".pcd"));
      entry.image = fs::absolute(out_dir_ / "images" / (candidate.id + ".png"));
      dataset.pairs.push_back(entry);
      summary_.pair_ids.push_back(candidate.id);
      pairs.push_back({{"id", candidate.id},
                       {"cloud_stamp_ns", candidate.cloud.stamp_ns},
                       {"image_stamp_ns", candidate.image->stamp_ns}});
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
  BoardSpec board_;
  BagImportOptions options_;
  ImportProgress progress_;
  int cloud_topic_ = -1, image_topic_ = -1, info_topic_ = -1;
  int image_width_ = 0, image_height_ = 0;
  int rings_ = 0;
  FirstPass first_;
  BagImportSummary summary_;
};

}  // namespace

BagImportSummary ImportBag(const fs::path& bag_path, const fs::path& out_dir,
                           const BoardSpec& board, BagImportOptions options,
                           const ImportProgress& progress) {
  return Importer(bag_path, out_dir, board, std::move(options), progress).Run();
}

}  // namespace calibench
