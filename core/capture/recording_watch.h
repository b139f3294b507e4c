// A recording followed while it is written (`calibench watch` on a .bag, .mcap, .db3 or rosbag2
// folder): its messages read as the recorder stores them, its pairs chosen exactly as `import`
// chooses them (core/capture/recording_pairs.h) and written as import writes them into a dataset
// folder (clouds/<id>.pcd, images/<id>.png; camera.yaml and dataset.json kept up to date, so
// that the folder can be calibrated at any moment).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/capture/bag_import.h"
#include "core/io/dataset.h"

namespace calibench {

// Whether `source` is a recording rather than a folder in the folder form: a file that starts
// like one (or is named like one and is not there yet), or a rosbag2 folder (metadata.yaml, or
// .mcap / .db3 files in it). What `watch` and `gui --watch` tell the two by.
bool IsRecordingSource(const std::filesystem::path& source);

struct RecordingUpdate {
  std::vector<PairEntry> pairs;    // new, in the order found
  std::vector<std::string> notes;  // what was chosen or is awaited, in words
  bool closed = false;             // the recorder closed the file and every pair of it is out
  bool data_arrived = false;       // messages came since the last look: the recording is alive
};

class GrowingRecording {
 public:
  // `board` nullopt: the target.json beside the recording, else the preset that fits (as
  // import). Nothing is read yet.
  GrowingRecording(std::filesystem::path recording, std::filesystem::path out_dir,
                   std::optional<BoardSpec> board, BagImportOptions options);
  ~GrowingRecording();

  // Reads what the recorder stored since the last call. Throws IoError naming the recording on
  // damaged data, ambiguous topics (the flag to pass), a board no preset explains.
  RecordingUpdate Poll();

  // The board, given while following (the workbench's pick; `source` says which): the pairs held
  // for want of one are searched with it. Ignored once a board is known.
  void SetBoard(const BoardSpec& board, const std::string& source);
  // Why no pair can come yet though a board is there (no preset explains it); empty otherwise.
  std::string BoardProblem() const;

  // The camera and the board, once the first pair is out (nullopt before); the dataset folder.
  std::optional<Dataset> Setup() const;
  const std::filesystem::path& OutDir() const { return out_dir_; }

 private:
  struct Pending;
  void ChooseTopicsWhenPresent(bool closed, RecordingUpdate* update);
  void Route(int topic, std::int64_t log_time_ns, std::span<const std::uint8_t> data);
  void WritePairs(RecordingUpdate* update);
  void WatchForTheBoard(RecordingUpdate* update);

  std::filesystem::path recording_, out_dir_;
  std::optional<BoardSpec> board_;
  std::string board_source_;
  BagImportOptions options_;
  std::unique_ptr<BagReader> reader_;
  std::unique_ptr<RecordingPairFinder> finder_;
  int cloud_topic_ = -1, image_topic_ = -1, info_topic_ = -1;
  std::vector<Pending> pending_;  // messages read before the topics were chosen
  Dataset dataset_;               // the pairs written so far
  bool said_waiting_ = false, finished_ = false;
  std::string said_board_problem_;  // the board problem last said (said once)
  std::string said_target_error_;   // a broken target file beside it, said once
  std::optional<std::pair<BoardSpec, std::string>> given_board_;  // before the finder exists
};

}  // namespace calibench
