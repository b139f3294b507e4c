// Where a followed capture's pairs come from: the folder a capture script fills
// (core/capture/folder_watch.h) or a recording being written (core/capture/recording_watch.h),
// behind one interface, so that `calibench watch` and the workbench's live session follow either
// with one loop over the pipeline job (core/session/calibration_job.h).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/capture/bag_import.h"
#include "core/capture/folder_watch.h"
#include "core/io/dataset.h"

namespace calibench {

struct FeedUpdate {
  std::vector<FolderEvent> events;  // complete pairs in capture order, incomplete stems, removals
  std::vector<std::string> notes;   // what the source chose or is waiting for, in words
  bool closed = false;              // nothing more will come (a recording closed by its recorder)
  // Data came though no pair did (a recording's messages): the capture is alive, not idle.
  bool data_arrived = false;
};

class CaptureFeed {
 public:
  virtual ~CaptureFeed() = default;
  // What happened since the last look (now_s: seconds on a monotonic clock). The first look
  // returns the pairs already there. Throws IoError naming the source on damaged data.
  virtual FeedUpdate Poll(double now_s) = 0;
  // The camera and the target, once known (a recording tells them with its first pair).
  virtual std::optional<Dataset> Setup() const = 0;
  // The folder that holds the pairs and the session (the watched folder, or where a recording's
  // pairs are written).
  virtual std::filesystem::path DatasetFolder() const = 0;
  // A recording whose board no preset explains: the board, picked by the user; false when the
  // source takes none (a folder's target.json says it).
  virtual bool SetBoard(const BoardSpec& /*board*/, const std::string& /*source*/) { return false; }
  // Why no pair can come though a board is visibly there; empty otherwise.
  virtual std::string BoardProblem() const { return ""; }
};

// A folder in the folder form whose camera and target (`setup`) are known.
std::unique_ptr<CaptureFeed> FollowFolder(Dataset setup, const std::filesystem::path& folder,
                                          const FolderWatchOptions& options);
// A recording being written, its pairs chosen as `import` chooses them and written to `out_dir`
// (`board` nullopt: the target.json beside the recording, else the preset that fits).
std::unique_ptr<CaptureFeed> FollowRecording(const std::filesystem::path& recording,
                                             const std::filesystem::path& out_dir,
                                             std::optional<BoardSpec> board,
                                             const BagImportOptions& options);

}  // namespace calibench
