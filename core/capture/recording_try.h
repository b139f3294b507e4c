// What core/capture/recording_pairs.cpp hands its second thread for one sweep tried (internal to
// core/io): the sweep's bytes, the nearest image and the others in its stillness window, copied
// out of the reader's window, and the camera they are judged with.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/base/image.h"
#include "core/camera/camera.h"
#include "core/recording/ros_messages.h"

namespace calibench::recording_detail {

using Bytes = std::shared_ptr<const std::vector<std::uint8_t>>;

inline Bytes Copy(std::span<const std::uint8_t> data) {
  return std::make_shared<const std::vector<std::uint8_t>>(data.begin(), data.end());
}

struct StampedBytes {
  std::int64_t stamp_ns = 0;
  Bytes bytes;
};

inline std::int64_t Ns(double seconds) { return std::llround(seconds * 1e9); }
// A message's stamp: its header's, or the time the recorder logged it when the header has none.
inline std::int64_t StampOr(const RosHeader& header, std::int64_t log_time_ns) {
  return header.stamp_ns != 0 ? header.stamp_ns : log_time_ns;
}

struct Try {
  int hold = 0;
  // A sweep of a board that never stopped (PairSelectionOptions::moving_after_s): `others` are
  // then every other frame within moving_images_s, searched each for the board.
  bool moving = false;
  // A ring-less LiDAR's moving sweep: a board its frames show still is a hold, tried blind with
  // the hold's sweeps integrated, not this sweep alone.
  bool ringless = false;
  StampedBytes cloud;
  StampedBytes image;                // the nearest in time
  std::vector<StampedBytes> others;  // the other images within the stillness window
  // A ring-less LiDAR's other sweeps within the integration span (PairSelectionOptions::
  // ringless_integration_s), integrated with `cloud` into the pair's cloud.
  std::vector<StampedBytes> integrated;
  CameraModel camera;
};

// A try with its image decoded (nullopt: unreadable), held while the board is not known.
struct HeldTry {
  Try attempt;
  std::optional<ImageU8> image;
};

}  // namespace calibench::recording_detail
