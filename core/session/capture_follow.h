// Following a capture while it is written (`calibench watch`): a folder in the folder form that a
// capture script fills, or a recording being written, pair by pair into the calibration job —
// detect, pre-flight, accept or reject, solve again, σ against the goal, the next pose — with the
// session and the feature cache saved after every solve. What happens is told to a sink as events
// (the command line prints them as words or JSON lines; docs/architecture.md, "The capture
// job").
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/board/board.h"
#include "core/capture/bag_import.h"
#include "core/capture/capture_feed.h"
#include "core/capture/folder_watch.h"
#include "core/session/calibration_job.h"
#include "core/session/feed_loop.h"
#include "core/session/follow_event.h"

namespace calibench {

struct CaptureFollowRequest {
  std::string source;              // a folder, a manifest in one, or a recording being written
  std::filesystem::path out;       // recordings: the dataset folder (default: as `import`'s)
  std::filesystem::path session;   // default: calibench.session.json in the dataset folder
  std::optional<BoardSpec> board;  // recordings: the board the camera sees
  BagImportOptions import;         // recordings: topics, camera, pair selection
  FolderWatchOptions folder;       // folders: when a file is complete, partners
  bool exit_when_done = false;     // end when the stop rule says done
  double idle_exit_s = 0.0;        // end after this long without new data [s] (0 = never)
  double poll_s = 0.1;             // between looks [s]
  FeedLoopOptions Loop() const;    // the loop's share of the above
  bool Check(std::string* why) const;
};

// The source as a feed, and where its session goes unless request.session says: a recording's
// pairs written to request.out (default: as `import`'s), a folder's camera and target waited for
// (told to `sink` as "waiting") until idle_exit_s passes or `stopped` (may be empty) says so.
// nullopt with *why when it cannot be followed. What FollowCapture and the workbench's live
// session both follow.
struct OpenedFeed {
  std::unique_ptr<CaptureFeed> feed;
  std::filesystem::path session;
};
std::optional<OpenedFeed> OpenCaptureFeed(CaptureFollowRequest request, const FollowSink& sink,
                                          const std::function<bool()>& stopped, std::string* why);

// OpenCaptureFeed one look at a time, for a front end that runs each look as a step (the
// workbench's worker): Try() every request.poll_s until it gives the feed or a reason.
class CaptureFeedOpener {
 public:
  CaptureFeedOpener(CaptureFollowRequest request, FollowSink sink);
  // The feed once it opens. nullopt with *why empty while a folder's camera and target are
  // awaited ("waiting", said once), with *why when the source cannot be followed or idle_exit_s
  // passed first. Throws IoError naming a file that does not read.
  std::optional<OpenedFeed> Try(std::string* why);

 private:
  CaptureFollowRequest request_;
  FollowSink sink_;
  double start_s_ = 0;
  bool resolved_ = false, said_ = false;
  std::filesystem::path folder_, manifest_;
};

// Follows until done (with exit_when_done), the recording is closed, or idle; the "end" event
// says which. False with *why when it cannot start: the source is not a folder or a recording,
// or the folder's camera and target never came (idle_exit_s passed first). Unreadable files
// throw IoError naming them.
bool FollowCapture(CaptureFollowRequest request, const CalibrationJobOptions& options,
                   const FollowSink& sink, std::string* why);

}  // namespace calibench
