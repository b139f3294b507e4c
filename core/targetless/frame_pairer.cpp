#include "core/targetless/frame_pairer.h"

#include <cstdlib>

#include "core/capture/bag_import.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"

namespace calibench {

CheckTopics ChooseCheckTopics(const BagReader& bag, const CheckInputOptions& options) {
  BagImportOptions wanted;
  wanted.cloud_topic = options.cloud_topic;
  wanted.image_topic = options.image_topic;
  wanted.camera_info_topic = options.camera_info_topic;
  wanted.camera = options.camera;
  ChooseTopics(bag, &wanted);
  CheckTopics topics;
  topics.encodings = ChosenPairTopics(bag, wanted);
  topics.cloud = bag.FindTopic(wanted.cloud_topic);
  topics.image = bag.FindTopic(wanted.image_topic);
  topics.camera_info = options.camera ? -1 : bag.FindTopic(wanted.camera_info_topic);
  topics.cloud_name = wanted.cloud_topic;
  topics.image_name = wanted.image_topic;
  topics.camera_info_name = wanted.camera_info_topic;
  return topics;
}

CheckFramePairer::CheckFramePairer(std::string source, PairTopics topics, const CheckOptions& check,
                                   const CheckInputOptions& options, CheckInputProgress progress)
    : source_(std::move(source)),
      topics_(std::move(topics)),
      check_(check),
      options_(options),
      progress_(std::move(progress)) {}

void CheckFramePairer::AddCloud(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
  const std::int64_t interval_ns = static_cast<std::int64_t>(options_.frame_interval_s * 1e9);
  if (pending_cloud_ || (last_frame_ns_ && log_time_ns - *last_frame_ns_ < interval_ns)) return;
  pending_cloud_ = Held{std::vector<std::uint8_t>(data.begin(), data.end()), log_time_ns};
}

void CheckFramePairer::AddImage(std::span<const std::uint8_t> data, std::int64_t log_time_ns) {
  Held image{std::vector<std::uint8_t>(data.begin(), data.end()), log_time_ns};
  const std::int64_t max_offset_ns = static_cast<std::int64_t>(options_.max_pair_offset_s * 1e9);
  // The cloud's partner is the image before it or the first after it, whichever is nearer.
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

void CheckFramePairer::MakeFrame(const Held& image_message) {
  const std::string id = "t" + std::to_string(pending_cloud_->time_ns);
  try {
    const LidarCloud cloud =
        DecodeCloudMessage(pending_cloud_->data, topics_.livox_cloud, topics_.cloud).cloud;
    const ImageU8 image = topics_.compressed_image
                              ? DecodeCompressedImage(image_message.data, topics_.image).image
                              : DecodeImage(image_message.data, topics_.image).image;
    frames_.push_back(MakeEdgeFrame(id, cloud, image, check_));
    last_frame_ns_ = pending_cloud_->time_ns;
    ++made_;
    if (progress_) progress_(made_, 0, id);
  } catch (const std::invalid_argument& e) {
    problems_.push_back(source_ + " at " + id + ": " + e.what());
  }
}

std::vector<EdgeFrame> CheckFramePairer::TakeFrames() { return std::exchange(frames_, {}); }

std::vector<std::string> CheckFramePairer::TakeProblems() { return std::exchange(problems_, {}); }

}  // namespace calibench
