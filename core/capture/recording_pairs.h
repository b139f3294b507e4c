// Pairs from a recording as it is read, message by message, for `import` (a finished recording)
// and `watch` (one still being written): the same pairs either way.
//
// The LiDAR decides where to look: every sweep is compared with the first sweep of its "hold"
// (core/lidar/cloud_motion.h), and only a sweep whose neighbours within the stillness window
// belong to its own hold is tried, once per hold (again `retry_s` later if that try gave no
// pair). A try searches one image for the board (the nearest in time) and follows its corners
// into the other images of the window by optical flow to check that the camera saw it still.
// Tries run on a second thread while the first reads and decompresses.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/io/load_limits.h"
#include "core/lidar/cloud.h"
#include "core/lidar/cloud_motion.h"
#include "core/recording/bag.h"

namespace calibench {

struct PairSelectionOptions {
  // Pairing: a cloud takes the image with the nearest stamp within this offset [s].
  double max_pair_offset_s = 0.05;
  // Stillness: the board poses the camera sees within ±window/2 of the pair [s] (a spinning
  // LiDAR sweeps for 100 ms) may differ from the pair's by at most these.
  double still_window_s = 0.4;
  double still_translation_m = 0.01;
  double still_rotation_deg = 1.0;
  // Near-duplicates: a pair whose board pose is within both of these of a kept pair's is dropped.
  double duplicate_translation_m = 0.10;
  double duplicate_rotation_deg = 5.0;
  // Where to look: sweeps that agree with their hold's first sweep.
  CloudMotionOptions lidar_motion;
  double retry_s = 1.0;  // a hold whose try gave no pair is tried again this much later
  // A LiDAR that never sees the scene still (a non-repeating scan, a busy street) must not hide
  // the board: after this long without a still sweep, a sweep is tried every `retry_s` anyway.
  double lidar_blind_s = 3.0;
  // A board that never stops (a waved capture; docs/architecture.md "Time"): once a spinning
  // LiDAR has seen nothing still for this long, every sweep is tried as a moving pair — the board
  // searched in each frame within `moving_images_s` of the sweep's stamp, the frames where it is
  // found kept with the pair (the camera's board track), with no stillness check and no
  // near-duplicate rule [s]; the motion's sweeps before that are tried too, once it has lasted
  // that long (the reader keeps that much more of the recording: moving_after_s + 1.5 s). Shorter
  // carries between still holds give no moving pair. 0: never.
  double moving_after_s = 2.0;
  // Either side of a moving sweep's stamp [s]: the offset's search window (0.25 s), the sweep's
  // own 0.1 s and a frame beyond.
  double moving_images_s = 0.45;
  // A moving sweep is a pair when its board is found in this many frames around it, at least
  // one on either side of its stamp (a track to place its returns on).
  int moving_min_frames = 3;
  // A moving try's board that travels less than both of these over its frames (from the nearest
  // frame's pose) was held still: a hold, where something else moved before the LiDAR.
  double moving_min_travel_m = 0.05;
  double moving_min_turn_deg = 3.0;
  // A LiDAR whose sweeps carry no rings (Livox-class: a 0.1 s frame leaves a far board a few
  // strokes of its rosette): the sweeps within this span centred on the tried one are integrated
  // into the pair's cloud, and the camera's stillness check spans it too [s]. 0: one sweep.
  double ringless_integration_s = 1.0;
  // Without a board given: the presets are tried on the tries' images until this many show one.
  int board_sample_images = 3;
  // A board that no preset is (one found only inside a larger print) ends the reading at once
  // with the reason (import); false: the recording is followed on, the reason in BoardProblem,
  // until SetBoard gives the board (watch).
  bool stop_on_unknown_board = true;
  LoadLimits limits;

  bool Check(std::string* why) const;
};

// How the chosen topics are serialized.
struct PairTopics {
  MessageEncoding cloud = MessageEncoding::kRos1;
  MessageEncoding image = MessageEncoding::kRos1;
  MessageEncoding camera_info = MessageEncoding::kRos1;
  bool compressed_image = false;               // sensor_msgs/CompressedImage rather than Image
  bool livox_cloud = false;                    // livox_ros_driver(2)/CustomMsg, not PointCloud2
  std::string image_topic, camera_info_topic;  // for messages
};

// A camera frame of a moving pair: its stamp and, the first time a pair holds it, its pixels
// (empty: handed out with an earlier pair, whose writer has it).
struct FoundFrame {
  std::int64_t stamp_ns = 0;
  ImageU8 image;
};

struct FoundPair {
  std::int64_t cloud_stamp_ns = 0, image_stamp_ns = 0;
  LidarCloud cloud;         // time_s after cloud_stamp_ns, where the driver gives them
  std::string point_times;  // how its per-point times were read, or why it has none
  ImageU8 image;            // a still pair's; a moving pair's nearest frame is in `frames`
  Pose cam_from_board = Pose::Identity();  // a moving pair's: at its nearest frame
  bool stillness_checked = true;           // false: no other image within the window
  // A moving pair's frames that show the board, by stamp (the nearest is image_stamp_ns's);
  // empty for a still pair.
  std::vector<FoundFrame> frames;
  bool Moving() const { return !frames.empty(); }
};

struct PairFinderStats {
  std::int64_t clouds = 0, images = 0;  // messages on the two topics
  int tries = 0;                        // sweeps tried
  int images_searched = 0;              // full board searches
  int boards_found = 0;                 // of those, the board found
  std::map<std::string, int> dropped;   // reason -> sweeps not paired for it
  int kept_without_stillness_check = 0;
  int moving_pairs = 0;      // of the pairs found, sweeps of a board that never stopped
  std::string board_choice;  // how the board was chosen, when it was not given
};

class RecordingPairFinder {
 public:
  // `source` names the recording in messages. `board` nullopt: chosen among the presets
  // (core/target/board_choice.h), or IoError when none fits. `camera` nullopt: from the
  // CameraInfo messages.
  RecordingPairFinder(std::string source, PairTopics topics, std::optional<BoardSpec> board,
                      std::optional<CameraModel> camera, PairSelectionOptions options);
  ~RecordingPairFinder();
  RecordingPairFinder(const RecordingPairFinder&) = delete;
  RecordingPairFinder& operator=(const RecordingPairFinder&) = delete;

  // Messages in the order the recording stores them. Throw IoError naming the source when the
  // data contradicts itself (images of another size than the intrinsics), or when the second
  // thread failed.
  void AddCloud(std::span<const std::uint8_t> data, std::int64_t log_time_ns);
  void AddImage(std::span<const std::uint8_t> data, std::int64_t log_time_ns);
  void AddCameraInfo(std::span<const std::uint8_t> data);
  // The last sweeps judged, every try finished. Throws IoError when no intrinsics came.
  void Finish();

  // Pairs found since the last call, in the order the tries were made (the same for any timing).
  std::vector<FoundPair> TakePairs();
  PairFinderStats Stats() const;
  std::optional<CameraModel> Camera() const;
  std::optional<BoardSpec> Board() const;
  // Why no board is known though one is visibly there ("...: no preset board explains the
  // images (...)"); empty otherwise. Only with stop_on_unknown_board false.
  std::string BoardProblem() const;
  // The board, given while following (`source` says by what): the held tries and every later one
  // are searched with it. Ignored once a board is known.
  void SetBoard(const BoardSpec& board, const std::string& source);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace calibench
