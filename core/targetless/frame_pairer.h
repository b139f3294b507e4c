// Clouds of a recording, each with the image nearest in time, thinned to one per interval and
// reduced to their edges (docs/targetless.md "Input"): what `check` reads from a whole recording
// and the drift meter (check_follow.h) from one still being written, message by message.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/capture/recording_pairs.h"
#include "core/targetless/check_input.h"

namespace calibench {

class BagReader;

// The topics a check reads from a recording, chosen as `import` chooses them unless the options
// name them: each one's index in the reader (camera_info -1 when the camera is given), its name,
// and how they are serialized. Throws IoError as ChooseTopics.
struct CheckTopics {
  PairTopics encodings;
  int cloud = -1, image = -1, camera_info = -1;
  std::string cloud_name, image_name, camera_info_name;
};
CheckTopics ChooseCheckTopics(const BagReader& bag, const CheckInputOptions& options);

class CheckFramePairer {
 public:
  // `source` names the recording in messages.
  CheckFramePairer(std::string source, PairTopics topics, const CheckOptions& check,
                   const CheckInputOptions& options, CheckInputProgress progress = {});
  // Messages of the two topics in the order the recording stores them.
  void AddCloud(std::span<const std::uint8_t> data, std::int64_t log_time_ns);
  void AddImage(std::span<const std::uint8_t> data, std::int64_t log_time_ns);
  // Frames made since the last call, and "source at t<stamp>: reason" for messages that could
  // not be decoded.
  std::vector<EdgeFrame> TakeFrames();
  std::vector<std::string> TakeProblems();
  int FramesMade() const { return made_; }

 private:
  struct Held {
    std::vector<std::uint8_t> data;
    std::int64_t time_ns = 0;
  };
  void MakeFrame(const Held& image_message);

  std::string source_;
  PairTopics topics_;
  CheckOptions check_;
  CheckInputOptions options_;
  CheckInputProgress progress_;
  std::optional<Held> pending_cloud_, last_image_;
  std::optional<std::int64_t> last_frame_ns_;
  std::vector<EdgeFrame> frames_;
  std::vector<std::string> problems_;
  int made_ = 0;
};

}  // namespace calibench
