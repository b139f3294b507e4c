#include "core/targetless/check_input.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "core/base/parallel.h"
#include "core/io/bag.h"
#include "core/io/bag_import.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/dataset_source.h"
#include "core/io/image_io.h"
#include "core/io/ros_messages.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

int Threads(int threads) { return threads > 0 ? threads : DefaultThreads(); }

CheckInput LoadDatasetFrames(const fs::path& path, const CheckOptions& check,
                             const CheckInputOptions& options, const CheckInputProgress& progress) {
  const Dataset dataset =
      LoadDataset(path, options.camera ? CameraFile::kOptional : CameraFile::kRequired,
                  TargetFile::kOptional);
  CheckInput input;
  input.camera = options.camera ? *options.camera : dataset.camera;
  input.source = "dataset";
  const size_t n = dataset.pairs.size();
  std::vector<std::optional<EdgeFrame>> frames(n);
  std::vector<std::string> problems(n);
  ParallelFor(
      n, Threads(options.threads),
      [&](size_t i) {
        const PairEntry& pair = dataset.pairs[i];
        try {
          const LidarCloud cloud = LoadCloud(pair.cloud);
          const ImageU8 image = LoadImage(pair.image);
          if (image.width != input.camera.width || image.height != input.camera.height)
            throw IoError(pair.image.string() + ": the image is " + std::to_string(image.width) +
                          "x" + std::to_string(image.height) + ", the camera " +
                          std::to_string(input.camera.width) + "x" +
                          std::to_string(input.camera.height));
          frames[i] = MakeEdgeFrame(pair.id, cloud, image, check);
        } catch (const std::exception& e) {
          problems[i] = e.what();
        }
      },
      [&](int done, size_t i) {
        if (progress) progress(done, static_cast<int>(n), dataset.pairs[i].id);
      });
  for (size_t i = 0; i < n; ++i) {
    if (frames[i]) input.frames.push_back(std::move(*frames[i]));
    if (!problems[i].empty()) input.unreadable.push_back(problems[i]);
  }
  return input;
}

// Clouds of a recording, each with the image nearest in time, thinned to one per interval.
class RecordingFrames {
 public:
  RecordingFrames(const fs::path& path, const CheckOptions& check, const CheckInputOptions& options,
                  const CheckInputProgress& progress)
      : path_(path), check_(check), options_(options), progress_(progress) {}

  CheckInput Read() {
    const std::unique_ptr<BagReader> bag = OpenBag(path_);
    BagImportOptions topics_wanted;
    topics_wanted.cloud_topic = options_.cloud_topic;
    topics_wanted.image_topic = options_.image_topic;
    topics_wanted.camera_info_topic = options_.camera_info_topic;
    topics_wanted.camera = options_.camera;
    ChooseTopics(*bag, &topics_wanted);
    topics_ = ChosenPairTopics(*bag, topics_wanted);
    cloud_topic_ = bag->FindTopic(topics_wanted.cloud_topic);
    image_topic_ = bag->FindTopic(topics_wanted.image_topic);
    const int info_topic = options_.camera ? -1 : bag->FindTopic(topics_wanted.camera_info_topic);
    if (options_.camera) camera_ = options_.camera;
    std::vector<bool> wanted(bag->Topics().size(), false);
    wanted[cloud_topic_] = wanted[image_topic_] = true;
    if (info_topic >= 0) wanted[info_topic] = true;
    bag->ForEachMessage(wanted, [&](const BagMessage& message) {
      if (message.topic == cloud_topic_)
        OnCloud(message);
      else if (message.topic == image_topic_)
        OnImage(message);
      else if (!camera_)
        camera_ = DecodeCameraInfo(message.data, topics_.camera_info).camera;
      return true;
    });
    if (!camera_)
      throw IoError(path_.string() + ": no camera intrinsics: the recording has no CameraInfo on " +
                    topics_wanted.camera_info_topic + "; give them with --camera FILE");
    CheckInput input;
    input.camera = *camera_;
    input.source = bag->Format();
    input.unreadable = unreadable_;
    // At most max_frames, spread evenly over the recording.
    const size_t n = frames_.size(), keep = std::min<size_t>(n, options_.max_frames);
    for (size_t k = 0; k < keep; ++k) input.frames.push_back(std::move(frames_[k * n / keep]));
    return input;
  }

 private:
  struct Held {
    std::vector<std::uint8_t> data;
    std::int64_t time_ns = 0;
  };

  void OnCloud(const BagMessage& message) {
    const std::int64_t interval_ns = static_cast<std::int64_t>(options_.frame_interval_s * 1e9);
    if (pending_cloud_ || (last_frame_ns_ && message.log_time_ns - *last_frame_ns_ < interval_ns))
      return;
    pending_cloud_ = Held{std::vector<std::uint8_t>(message.data.begin(), message.data.end()),
                          message.log_time_ns};
  }

  void OnImage(const BagMessage& message) {
    Held image{std::vector<std::uint8_t>(message.data.begin(), message.data.end()),
               message.log_time_ns};
    const std::int64_t max_offset_ns = static_cast<std::int64_t>(options_.max_pair_offset_s * 1e9);
    if (pending_cloud_ && image.time_ns >= pending_cloud_->time_ns) {
      const Held* best = &image;
      if (last_image_ && std::llabs(last_image_->time_ns - pending_cloud_->time_ns) <
                             std::llabs(image.time_ns - pending_cloud_->time_ns))
        best = &*last_image_;
      if (std::llabs(best->time_ns - pending_cloud_->time_ns) <= max_offset_ns) MakeFrame(*best);
      pending_cloud_.reset();
    }
    last_image_ = std::move(image);
  }

  void MakeFrame(const Held& image_message) {
    const std::string id = "t" + std::to_string(pending_cloud_->time_ns);
    try {
      const LidarCloud cloud = DecodePointCloud2(pending_cloud_->data, topics_.cloud).cloud;
      const ImageU8 image = topics_.compressed_image
                                ? DecodeCompressedImage(image_message.data, topics_.image).image
                                : DecodeImage(image_message.data, topics_.image).image;
      frames_.push_back(MakeEdgeFrame(id, cloud, image, check_));
      last_frame_ns_ = pending_cloud_->time_ns;
      if (progress_) progress_(static_cast<int>(frames_.size()), 0, id);
    } catch (const std::invalid_argument& e) {
      unreadable_.push_back(path_.string() + " at " + id + ": " + e.what());
    }
  }

  fs::path path_;
  const CheckOptions& check_;
  const CheckInputOptions& options_;
  const CheckInputProgress& progress_;
  PairTopics topics_;
  int cloud_topic_ = -1, image_topic_ = -1;
  std::optional<CameraModel> camera_;
  std::optional<Held> pending_cloud_, last_image_;
  std::optional<std::int64_t> last_frame_ns_;
  std::vector<EdgeFrame> frames_;
  std::vector<std::string> unreadable_;
};

}  // namespace

bool CheckInputOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(frame_interval_s >= 0)) return fail("the frame interval must be >= 0 s");
  if (!(max_pair_offset_s > 0)) return fail("the pairing offset must be > 0 s");
  if (max_frames < 1) return fail("at least one frame");
  if (camera && !camera->Check(why)) return false;
  return true;
}

CheckInput LoadCheckInput(const fs::path& path, const CheckOptions& check,
                          const CheckInputOptions& options, const CheckInputProgress& progress) {
  std::string why;
  const std::optional<DatasetSource> source = RecogniseDataset(path, &why);
  CheckInput input;
  if (source && source->kind == DatasetKind::kRecording)
    input = RecordingFrames(path, check, options, progress).Read();
  else
    input = LoadDatasetFrames(path, check, options, progress);
  if (input.frames.empty()) {
    std::string reasons;
    for (const std::string& r : input.unreadable) reasons += "; " + r;
    throw IoError(path.string() + ": no frame to check (no cloud with an image)" + reasons);
  }
  return input;
}

}  // namespace calibench
