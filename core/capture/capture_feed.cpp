#include "core/capture/capture_feed.h"

#include "core/capture/recording_watch.h"

namespace calibench {
namespace {

class FolderFeed final : public CaptureFeed {
 public:
  FolderFeed(Dataset setup, const std::filesystem::path& folder, const FolderWatchOptions& options)
      : setup_(std::move(setup)), folder_(std::filesystem::absolute(folder), options) {}
  FeedUpdate Poll(double now_s) override { return {folder_.Poll(now_s), {}, false, false}; }
  std::optional<Dataset> Setup() const override { return setup_; }
  std::filesystem::path DatasetFolder() const override { return folder_.folder(); }

 private:
  Dataset setup_;
  GrowingFolder folder_;
};

class RecordingFeed final : public CaptureFeed {
 public:
  RecordingFeed(const std::filesystem::path& recording, const std::filesystem::path& out_dir,
                std::optional<BoardSpec> board, const BagImportOptions& options)
      : recording_(std::filesystem::absolute(recording), out_dir, std::move(board), options) {}
  FeedUpdate Poll(double) override {
    RecordingUpdate update = recording_.Poll();
    FeedUpdate feed{{}, std::move(update.notes), update.closed, update.data_arrived};
    for (PairEntry& pair : update.pairs) {
      FolderEvent event;
      event.stem = pair.id;
      event.pair = std::move(pair);
      feed.events.push_back(std::move(event));
    }
    return feed;
  }
  std::optional<Dataset> Setup() const override { return recording_.Setup(); }
  std::filesystem::path DatasetFolder() const override { return recording_.OutDir(); }
  bool SetBoard(const BoardSpec& board, const std::string& source) override {
    recording_.SetBoard(board, source);
    return true;
  }
  std::string BoardProblem() const override { return recording_.BoardProblem(); }

 private:
  GrowingRecording recording_;
};

}  // namespace

std::unique_ptr<CaptureFeed> FollowFolder(Dataset setup, const std::filesystem::path& folder,
                                          const FolderWatchOptions& options) {
  return std::make_unique<FolderFeed>(std::move(setup), folder, options);
}

std::unique_ptr<CaptureFeed> FollowRecording(const std::filesystem::path& recording,
                                             const std::filesystem::path& out_dir,
                                             std::optional<BoardSpec> board,
                                             const BagImportOptions& options) {
  return std::make_unique<RecordingFeed>(recording, out_dir, std::move(board), options);
}

}  // namespace calibench
