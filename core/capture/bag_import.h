// A recording -> a dataset folder: the LiDAR and camera topics chosen, clouds paired with images
// by stamp, the moments when the board stood still (no near-duplicate poses) or, where it never
// stops, every sweep that sees it with the frames around it; at most a cap;
// written as binary PCD + PNG + camera.yaml + dataset.json, with a record of every dropped frame.
// The pairs themselves are chosen by core/capture/recording_pairs.h, which `watch` shares.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/capture/recording_pairs.h"
#include "core/io/dataset.h"
#include "core/io/load_limits.h"
#include "core/recording/bag.h"

namespace calibench {

struct BagImportOptions : PairSelectionOptions {
  // Topics; empty = chosen automatically when the recording has exactly one candidate.
  std::string cloud_topic;            // sensor_msgs/PointCloud2
  std::string image_topic;            // sensor_msgs/Image or CompressedImage
  std::string camera_info_topic;      // sensor_msgs/CameraInfo; unused when `camera` is given
  std::optional<CameraModel> camera;  // intrinsics from a file instead of the recording
  // At most this many pairs, spread evenly over the recording (0 = no cap).
  int max_pairs = 60;

  bool Check(std::string* why) const;
};

// What an import did. Every cloud of the chosen topic is either written or counted under one
// reason in `dropped`.
struct BagImportSummary {
  std::string format;  // the reader's description of the file
  // A recording its recorder never closed, read up to its last complete record: where it stops
  // (BagReader::CutShort, naming the file); empty for a whole recording.
  std::string cut_short;
  std::string cloud_topic, image_topic, camera_source;
  std::int64_t clouds = 0;            // messages on the cloud topic
  std::int64_t images = 0;            // messages on the image topic
  int tries = 0;                      // sweeps tried (the LiDAR saw the board held still)
  int images_searched = 0;            // images searched for the board
  int boards_seen = 0;                // of those, the board found
  std::vector<std::string> pair_ids;  // written, in time order
  std::vector<std::int64_t> pair_cloud_stamps_ns;  // each written pair's sweep, as pair_ids
  std::map<std::string, int> dropped;              // reason -> clouds dropped for it
  // Kept pairs with no other image within the stillness window (a camera as slow as the
  // window): their stillness is unknown.
  int kept_without_stillness_check = 0;
  BoardSpec board;           // the board the pairs show
  std::string board_source;  // "--board", "<path> (beside the recording)" or how it was chosen
  double recording_seconds = 0.0;  // from the first to the last message read
  std::filesystem::path manifest;  // the dataset.json written
  std::int64_t bytes_read = 0;
  // How the LiDAR's per-point times were read (core/lidar/point_times.h), or why the clouds have
  // none and are taken as instantaneous; said once, from the first pair written.
  std::string point_times;
  int pairs_with_point_times = 0;  // of the pairs kept, their clouds' field `t` written
  // Of the pairs kept, sweeps of a board that never stopped, each with the frames around it
  // (the manifest's "images"; PairSelectionOptions::moving_after_s).
  int moving_pairs = 0;
};

// Topics to import when the options name none: exactly one PointCloud2 topic; one image topic
// (a raw Image is preferred over a CompressedImage of the same camera only when it is the only
// raw one); the CameraInfo beside the image topic (same namespace) or the only one. Throws
// IoError naming the file and listing the candidates when the choice is ambiguous or impossible.
void ChooseTopics(const BagReader& bag, BagImportOptions* options);

// A rig's cameras in a recording: every image topic with a CameraInfo beside it (same
// namespace), a raw topic's /compressed republish counted once. What `import --all-cameras` takes.
std::vector<std::string> CameraTopicsWithInfo(const BagReader& bag);

// Where an import of `bag` goes unless the user says otherwise: "<bag name>.dataset" beside it,
// or, when that folder cannot be written (a recording on a read-only medium), the same name
// under $XDG_DATA_HOME/calibench/imports (else ~/.local/share/calibench/imports).
std::filesystem::path DefaultImportFolder(const std::filesystem::path& bag);

// Progress of an import: the phase ("reading", "writing"), bytes done and in all.
using ImportProgress =
    std::function<void(const std::string& phase, std::int64_t done, std::int64_t total)>;

// The target file a user keeps with a recording: <recording>.target.json beside it (rig.mcap:
// rig.target.json), else target.json inside the rosbag2 folder or beside the recording, else the
// only *.target.json beside it (as `calibench target` names them). nullopt when there is none, or
// several that nothing tells apart.
std::optional<std::filesystem::path> TargetBesideRecording(const std::filesystem::path& bag);

// What import and watch share: the board as the user gave it, else from the target.json beside
// the recording (*source says which; nullopt and "" = chosen among the presets later); the chosen
// topics' serializations; a found pair written as clouds/<id>.pcd + images/<id>.png under
// `dir` (its entry, with absolute paths).
std::optional<BoardSpec> RecordingBoard(const std::filesystem::path& bag,
                                        const std::optional<BoardSpec>& given, std::string* source);
PairTopics ChosenPairTopics(const BagReader& bag, const BagImportOptions& options);
// A recording being written (followed): whether a PointCloud2, an image and (unless the camera is
// given) a CameraInfo topic have each brought a message yet — a recorder may announce a topic
// before its first message; only then can the topics be chosen. What watch and the drift meter
// wait for.
bool PairTopicsPresent(const BagReader& bag, bool camera_given);
PairEntry WriteFoundPair(const FoundPair& pair, const std::filesystem::path& dir,
                         const std::string& id);

// Reads the recording once (core/capture/recording_pairs.h chooses the pairs as it goes) and writes
// the dataset into `out_dir` (created; files already there with the same names are replaced,
// others kept). `board` nullopt: the target.json beside the recording, else the preset that
// fits the images. Throws IoError naming the file on unreadable data, on a camera that cannot be
// had, on a board no preset explains, or when no pair survives (the reasons in the message).
BagImportSummary ImportBag(const std::filesystem::path& bag_path,
                           const std::filesystem::path& out_dir,
                           const std::optional<BoardSpec>& board, BagImportOptions options,
                           const ImportProgress& progress = {});

}  // namespace calibench
