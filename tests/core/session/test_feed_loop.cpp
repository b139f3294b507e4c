// The one capture-follow loop (core/session/feed_loop.h) over a scripted feed: what `watch` and the
// workbench's live session both rely on — the capture opens once, when its setup is known and the
// first look has caught up, with every pair read so far; later pairs come in batches; the loop ends
// when closed, idle, stopped or done, and says the feed's notes and a pair's missing files.
#include <gtest/gtest.h>

#include <deque>

#include "core/session/feed_loop.h"

namespace calibench {
namespace {

PairEntry Pair(const std::string& id) {
  PairEntry pair;
  pair.id = id;
  pair.cloud = "clouds/" + id + ".pcd";
  pair.image = "images/" + id + ".png";
  return pair;
}

FeedUpdate Complete(std::initializer_list<const char*> ids) {
  FeedUpdate update;
  for (const char* id : ids) {
    FolderEvent event;
    event.kind = FolderEvent::Kind::kPairComplete;
    event.stem = id;
    event.pair = Pair(id);
    update.events.push_back(event);
  }
  return update;
}

// One scripted update per look (then empty ones); the setup known from look `setup_at` on.
class ScriptedFeed final : public CaptureFeed {
 public:
  ScriptedFeed(std::deque<FeedUpdate> script, int setup_at)
      : script_(std::move(script)), setup_at_(setup_at) {}
  FeedUpdate Poll(double) override {
    ++looks;
    if (script_.empty()) return {};
    FeedUpdate next = script_.front();
    script_.pop_front();
    return next;
  }
  std::optional<Dataset> Setup() const override {
    if (looks < setup_at_) return std::nullopt;
    Dataset setup;
    setup.camera.width = 640;
    return setup;
  }
  std::filesystem::path DatasetFolder() const override { return "/capture"; }
  int looks = 0;

 private:
  std::deque<FeedUpdate> script_;
  int setup_at_;
};

struct Followed {
  std::vector<std::vector<std::string>> opened, added;  // the pairs' ids, per call
  std::vector<std::string> said;                        // "event name: reason"
  FeedHandlers Handlers() {
    FeedHandlers handlers;
    handlers.open = [this](Dataset read, double) {
      EXPECT_EQ(read.manifest, "/capture");
      EXPECT_EQ(read.camera.width, 640);
      opened.push_back(Ids(read.pairs));
      return false;
    };
    handlers.add = [this](std::vector<PairEntry> pairs, double) {
      added.push_back(Ids(pairs));
      return false;
    };
    return handlers;
  }
  FollowSink Sink() {
    return
        [this](const FollowEvent& e) { said.push_back(e.event + " " + e.name + ": " + e.reason); };
  }
  static std::vector<std::string> Ids(const std::vector<PairEntry>& pairs) {
    std::vector<std::string> ids;
    for (const PairEntry& pair : pairs) ids.push_back(pair.id);
    return ids;
  }
};

FeedLoopOptions Fast(double first_look_s = 0.0, double idle_exit_s = 0.3) {
  FeedLoopOptions options;
  options.poll_s = 0.01;
  options.first_look_s = first_look_s;
  options.idle_exit_s = idle_exit_s;
  return options;
}

TEST(FeedLoop, OpensOnceCaughtUpWithEveryPairReadThenAddsEachBatch) {
  // Two looks bring pairs before the capture is caught up; a quiet look opens it with all three.
  std::deque<FeedUpdate> script = {
      Complete({"0000", "0001"}), Complete({"0002"}), FeedUpdate{},
      Complete({"0003"}),         FeedUpdate{},       Complete({"0004", "0005"})};
  script.back().closed = true;
  ScriptedFeed feed(script, 0);
  Followed followed;
  EXPECT_EQ(FollowFeed(feed, Fast(), followed.Handlers(), followed.Sink()), FeedEnd::kClosed);
  ASSERT_EQ(followed.opened.size(), 1u);
  EXPECT_EQ(followed.opened[0], (std::vector<std::string>{"0000", "0001", "0002"}));
  ASSERT_EQ(followed.added.size(), 2u);
  EXPECT_EQ(followed.added[0], std::vector<std::string>{"0003"});
  EXPECT_EQ(followed.added[1], (std::vector<std::string>{"0004", "0005"}));
  EXPECT_EQ(feed.looks, 6);
}

TEST(FeedLoop, ARecordingOpensWhenItsFirstPairTellsTheSetupAndTheFirstLookLasts) {
  // No setup for the first three looks (a recording's board not known yet), then pairs; the first
  // look lasts at least 0.15 s, so that the quiet looks before it do not open the capture.
  std::deque<FeedUpdate> script = {FeedUpdate{}, FeedUpdate{}, FeedUpdate{}, Complete({"a"})};
  ScriptedFeed feed(script, 3);
  Followed followed;
  FeedHandlers handlers = followed.Handlers();
  int looked = 0;
  handlers.looked = [&](const CaptureFeed& f, const FeedUpdate&) {
    EXPECT_EQ(&f, &feed);
    ++looked;
  };
  EXPECT_EQ(FollowFeed(feed, Fast(0.15, 0.3), handlers, followed.Sink()), FeedEnd::kIdle);
  ASSERT_EQ(followed.opened.size(), 1u);
  EXPECT_EQ(followed.opened[0], std::vector<std::string>{"a"});
  EXPECT_TRUE(followed.added.empty());
  EXPECT_EQ(looked, feed.looks);
  EXPECT_GE(feed.looks, 15);  // 0.15 s of looks at 0.01 s before it opened, then 0.3 s idle
}

TEST(FeedLoop, DataWithoutPairsKeepsItAliveAndTheIdleEndCountsFromTheLastData) {
  std::deque<FeedUpdate> script;
  for (int i = 0; i < 40; ++i) {
    FeedUpdate messages;  // a recording's messages that make no pair (its board unknown)
    messages.data_arrived = true;
    script.push_back(messages);
  }
  ScriptedFeed feed(script, 1000);
  Followed followed;
  EXPECT_EQ(FollowFeed(feed, Fast(0.0, 0.1), followed.Handlers(), followed.Sink()), FeedEnd::kIdle);
  EXPECT_GE(feed.looks, 41);  // every look with data, then quiet ones for 0.1 s
  EXPECT_TRUE(followed.opened.empty());
}

TEST(FeedLoop, StoppedDoneAndWhatTheLooksSay) {
  {  // stopped before the first look
    ScriptedFeed feed({Complete({"0000"})}, 0);
    Followed followed;
    FeedHandlers handlers = followed.Handlers();
    handlers.stopped = [] { return true; };
    EXPECT_EQ(FollowFeed(feed, Fast(), handlers, followed.Sink()), FeedEnd::kStopped);
    EXPECT_EQ(feed.looks, 0);
  }
  {  // the goal met when the capture opens: done at once
    ScriptedFeed feed({Complete({"0000"})}, 0);
    Followed followed;
    FeedHandlers handlers = followed.Handlers();
    handlers.open = [](Dataset, double) { return true; };
    EXPECT_EQ(FollowFeed(feed, Fast(), handlers, followed.Sink()), FeedEnd::kDone);
    EXPECT_EQ(feed.looks, 2);
  }
  {  // notes, a missing partner, a removed file and a picked board a folder does not take
    FeedUpdate said = Complete({"0000"});
    said.notes = {"camera from camera.yaml"};
    FolderEvent incomplete;
    incomplete.kind = FolderEvent::Kind::kIncomplete;
    incomplete.stem = "0001";
    incomplete.reason = "images/0001.png never came";
    FolderEvent removed = incomplete;
    removed.kind = FolderEvent::Kind::kRemoved;
    removed.reason = "clouds/0001.pcd was removed";
    said.events.push_back(incomplete);
    said.events.push_back(removed);
    ScriptedFeed feed({said}, 0);
    Followed followed;
    FeedHandlers handlers = followed.Handlers();
    bool picked = false;
    handlers.take_picked_board = [&]() -> std::optional<std::pair<BoardSpec, std::string>> {
      if (picked) return std::nullopt;
      picked = true;
      return std::make_pair(BoardSpec{}, "picked");
    };
    EXPECT_EQ(FollowFeed(feed, Fast(0.0, 0.05), handlers, followed.Sink()), FeedEnd::kIdle);
    EXPECT_EQ(followed.said,
              (std::vector<std::string>{"board : this capture's board comes from its target.json",
                                        "note : camera from camera.yaml",
                                        "incomplete 0001: images/0001.png never came",
                                        "removed 0001: clouds/0001.pcd was removed"}));
    ASSERT_EQ(followed.opened.size(), 1u);
    EXPECT_EQ(followed.opened[0], std::vector<std::string>{"0000"});
  }
  std::string why;
  FeedLoopOptions bad = Fast();
  bad.poll_s = 0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("poll"), std::string::npos);
}

}  // namespace
}  // namespace calibench
