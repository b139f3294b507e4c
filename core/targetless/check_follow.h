// The drift meter (docs/targetless.md "Live"): a recording followed while it is written — a drive
// after calibration — its frames reduced to edges as they arrive, and the check run again over
// the frames so far every few new ones: the estimate and its σ as they tighten, and the verdict
// once it is sure (the same verdict, other than "cannot tell", at two checks in a row).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/capture/recording_pairs.h"
#include "core/targetless/check.h"
#include "core/targetless/check_input.h"

namespace calibench {

class BagReader;
class CheckFramePairer;

struct DriftMeterOptions {
  int first_check_frames = 4;  // the first check waits for this many frames
  int recheck_every = 4;       // then runs again after this many new ones
  bool Check(std::string* why) const;
};

struct DriftUpdate {
  std::vector<std::string> notes;  // topics chosen, frames skipped, waiting, in words
  int new_frames = 0;
  int frames = 0;                     // held now (at most CheckInputOptions::max_frames)
  int frames_seen = 0;                // made since the start
  std::optional<CheckReport> report;  // when a check ran at this poll
  bool sure = false;                  // the verdict has held at two checks in a row
  bool closed = false;                // the recorder closed the file; a last check ran if needed
  bool data_arrived = false;
};

class DriftMeter {
 public:
  // R and its covariance on camera axes (CameraAxesCovariance). Nothing is read yet.
  DriftMeter(std::filesystem::path recording, Pose reference, Mat6 reference_covariance,
             CheckOptions check, CheckInputOptions input, DriftMeterOptions options);
  ~DriftMeter();
  DriftMeter(const DriftMeter&) = delete;
  DriftMeter& operator=(const DriftMeter&) = delete;
  // Reads what the recorder stored since the last call, and checks when enough is new. Throws
  // IoError naming the recording on damaged data or ambiguous topics.
  DriftUpdate Poll();
  std::optional<CameraModel> Camera() const { return camera_; }

 private:
  struct Pending;
  void ChooseTopicsWhenPresent(bool closed, DriftUpdate* update);
  void Route(int topic, std::int64_t log_time_ns, std::span<const std::uint8_t> data);
  void Keep(std::vector<EdgeFrame> frames);

  std::filesystem::path recording_;
  Pose reference_;
  Mat6 reference_covariance_;
  CheckOptions check_;
  CheckInputOptions input_;
  DriftMeterOptions options_;
  std::unique_ptr<BagReader> reader_;
  std::unique_ptr<CheckFramePairer> pairer_;
  std::vector<Pending> pending_;
  int cloud_topic_ = -1, image_topic_ = -1, info_topic_ = -1;
  PairTopics topics_;
  std::optional<CameraModel> camera_;
  std::vector<EdgeFrame> frames_;
  int frames_seen_ = 0, frames_at_last_check_ = 0;
  std::optional<CheckVerdict> last_verdict_;
  bool said_waiting_ = false, finished_ = false;
};

}  // namespace calibench
