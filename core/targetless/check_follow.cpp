#include "core/targetless/check_follow.h"

#include "core/capture/bag_import.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "core/targetless/frame_pairer.h"

namespace calibench {
namespace {

constexpr size_t kMaxPending = 4000;  // messages held before the topics are known

}  // namespace

struct DriftMeter::Pending {
  int topic = 0;
  std::int64_t log_time_ns = 0;
  std::vector<std::uint8_t> data;
};

bool DriftMeterOptions::Check(std::string* why) const {
  if (first_check_frames >= 1 && recheck_every >= 1) return true;
  if (why) *why = "the drift meter needs >= 1 frame before its first check and between checks";
  return false;
}

DriftMeter::DriftMeter(std::filesystem::path recording, Pose reference, Mat6 reference_covariance,
                       CheckOptions check, CheckInputOptions input, DriftMeterOptions options)
    : recording_(std::move(recording)),
      reference_(reference),
      reference_covariance_(reference_covariance),
      check_(std::move(check)),
      input_(std::move(input)),
      options_(options),
      camera_(input_.camera) {}

DriftMeter::~DriftMeter() = default;

DriftUpdate DriftMeter::Poll() {
  DriftUpdate update;
  if (finished_) {
    update.closed = true;
    return update;
  }
  if (!reader_) {
    try {
      reader_ = OpenBagToFollow(recording_);
    } catch (const IoError& error) {
      if (!said_waiting_) update.notes.push_back(std::string("waiting: ") + error.what());
      said_waiting_ = true;
      return update;
    }
  }
  const bool closed = reader_->FollowNewMessages([&](const BagMessage& message) {
    update.data_arrived = true;
    if (pairer_) {
      Route(message.topic, message.log_time_ns, message.data);
    } else {
      if (pending_.size() == kMaxPending) pending_.erase(pending_.begin());
      pending_.push_back({message.topic, message.log_time_ns,
                          std::vector<std::uint8_t>(message.data.begin(), message.data.end())});
    }
    return true;
  });
  if (!pairer_) ChooseTopicsWhenPresent(closed, &update);
  if (closed && !pairer_)
    throw IoError(recording_.string() +
                  ": the recording was closed without a PointCloud2 and an image topic");
  std::vector<EdgeFrame> made = pairer_->TakeFrames();
  for (const std::string& problem : pairer_->TakeProblems())
    update.notes.push_back("skipped " + problem);
  update.new_frames = static_cast<int>(made.size());
  Keep(std::move(made));
  update.frames = static_cast<int>(frames_.size());
  update.frames_seen = frames_seen_;
  const int new_since_check = frames_seen_ - frames_at_last_check_;
  const bool enough = frames_seen_ >= options_.first_check_frames &&
                      (frames_at_last_check_ == 0 || new_since_check >= options_.recheck_every);
  const bool last_look = closed && new_since_check > 0;
  if (camera_ && !frames_.empty() && (enough || last_look)) {
    update.report = CheckCalibration(frames_, *camera_, reference_, reference_covariance_, check_);
    frames_at_last_check_ = frames_seen_;
    const CheckVerdict verdict = update.report->verdict;
    update.sure = verdict != CheckVerdict::kCannotTell && last_verdict_ == verdict;
    last_verdict_ = verdict;
  }
  if (closed) {
    finished_ = true;
    update.closed = true;
    if (!camera_)
      throw IoError(recording_.string() +
                    ": no camera intrinsics: the recording has no "
                    "CameraInfo; give them with --camera FILE");
  }
  return update;
}

void DriftMeter::ChooseTopicsWhenPresent(bool closed, DriftUpdate* update) {
  if (!PairTopicsPresent(*reader_, input_.camera.has_value()) && !closed) return;
  const CheckTopics chosen = ChooseCheckTopics(*reader_, input_);
  topics_ = chosen.encodings;
  cloud_topic_ = chosen.cloud;
  image_topic_ = chosen.image;
  info_topic_ = chosen.camera_info;
  pairer_ = std::make_unique<CheckFramePairer>(recording_.string(), topics_, check_, input_);
  update->notes.push_back("topics: clouds " + chosen.cloud_name + ", images " + chosen.image_name +
                          ", camera " +
                          (input_.camera ? "from --camera" : chosen.camera_info_name));
  for (const Pending& message : pending_) Route(message.topic, message.log_time_ns, message.data);
  pending_.clear();
}

void DriftMeter::Route(int topic, std::int64_t log_time_ns, std::span<const std::uint8_t> data) {
  if (topic == cloud_topic_) {
    pairer_->AddCloud(data, log_time_ns);
  } else if (topic == image_topic_) {
    pairer_->AddImage(data, log_time_ns);
  } else if (topic == info_topic_ && info_topic_ >= 0 && !camera_) {
    camera_ = DecodeCameraInfo(data, topics_.camera_info).camera;
  }
}

// A drive's frames spread over all of it: past max_frames, every other one is let go.
void DriftMeter::Keep(std::vector<EdgeFrame> frames) {
  for (EdgeFrame& frame : frames) {
    frames_.push_back(std::move(frame));
    ++frames_seen_;
    if (static_cast<int>(frames_.size()) <= input_.max_frames) continue;
    std::vector<EdgeFrame> thinned;
    for (size_t i = 0; i < frames_.size(); i += 2) thinned.push_back(std::move(frames_[i]));
    frames_ = std::move(thinned);
  }
}

}  // namespace calibench
