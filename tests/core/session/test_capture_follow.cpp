// Following a capture (core/session/capture_follow.h) through its events, without the command
// line: a finished folder followed to its end, a source that is not a folder, a folder whose
// camera and target never come.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/session/capture_follow.h"
#include "core/session/session.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

struct Heard {
  std::vector<FollowEvent> events;
  std::vector<std::string> said(const std::string& kind) const {
    std::vector<std::string> out;
    for (const FollowEvent& e : events)
      if (e.event == kind) out.push_back(e.name + ": " + e.reason);
    return out;
  }
};

// A finished folder followed until `idle_exit_s` without new files (its files settle at once).
CaptureFollowRequest FolderRequest(const fs::path& folder, double idle_exit_s) {
  CaptureFollowRequest request;
  request.source = folder.string();
  request.idle_exit_s = idle_exit_s;
  request.folder.settle_s = 0.05;
  return request;
}

TEST(CaptureFollow, AFolderIsFollowedToItsEndWithEveryPairsVerdict) {
  SimOptions sim = SimPreset("demo");
  sim.num_pairs = 5;
  sim.seed = 11;
  const fs::path dir = test::TempDir("capture_follow");
  fs::remove_all(dir);
  const Dataset dataset = SimulateDataset(sim, dir / "capture");
  Heard heard;
  int solves = 0;
  const CaptureFollowRequest request = FolderRequest(dir / "capture", 1.0);
  std::string why;
  ASSERT_TRUE(FollowCapture(
      request, CalibrationJobOptions{},
      [&](const FollowEvent& e) {
        FollowEvent copy = e;
        if (e.event == "solve") {
          ASSERT_NE(e.advice, nullptr);
          EXPECT_GE(e.latency_s, 0.0);
          ++solves;
          copy.advice = nullptr;  // valid during the call only
        }
        heard.events.push_back(copy);
      },
      &why))
      << why;
  int accepted = 0;
  for (const FollowEvent& e : heard.events) accepted += e.event == "pair" && e.accepted;
  EXPECT_EQ(accepted, 5) << ::testing::PrintToString(heard.said("pair"));
  EXPECT_GE(solves, 1);
  ASSERT_FALSE(heard.events.empty());
  EXPECT_EQ(heard.events.back().event, "end");
  EXPECT_EQ(heard.events.back().reason, "no new data for 1 s");
  // The session beside the capture holds every pair.
  EXPECT_TRUE(fs::exists(dir / "capture" / "calibench.session.json"));
  EXPECT_EQ(dataset.pairs.size(), 5u);
}

TEST(CaptureFollow, WhatCannotBeFollowedIsSaid) {
  const fs::path dir = test::TempDir("capture_follow_refused");
  fs::remove_all(dir);
  fs::create_directories(dir / "empty");
  Heard heard;
  const FollowSink sink = [&](const FollowEvent& e) { heard.events.push_back(e); };
  CaptureFollowRequest request;
  request.source = (dir / "nowhere").string();
  std::string why;
  EXPECT_FALSE(FollowCapture(request, CalibrationJobOptions{}, sink, &why));
  EXPECT_NE(why.find((dir / "nowhere").string() + " is not a folder"), std::string::npos) << why;
  // A folder without its camera and target: waited for, then the idle exit says what was missing.
  request.source = (dir / "empty").string();
  request.idle_exit_s = 0.3;
  why.clear();
  EXPECT_FALSE(FollowCapture(request, CalibrationJobOptions{}, sink, &why));
  EXPECT_FALSE(why.empty());
  ASSERT_EQ(heard.said("waiting").size(), 1u);
  EXPECT_NE(heard.said("waiting")[0].find("camera.yaml and target.json"), std::string::npos);
  ASSERT_FALSE(heard.events.empty());
  EXPECT_EQ(heard.events.back().event, "end");
  EXPECT_EQ(heard.events.back().reason, why);
  // A negative idle time is refused before anything is looked at.
  request.idle_exit_s = -1;
  EXPECT_FALSE(FollowCapture(request, CalibrationJobOptions{}, sink, &why));
  EXPECT_NE(why.find("--idle-exit must be >= 0"), std::string::npos) << why;
}

// A session that is not this capture's (another dataset's, or one that does not load) is not
// resumed: the follower says so, naming it, and it is kept as the autosave's first backup.
TEST(CaptureFollow, ASessionOfAnotherDatasetIsSaidAndKeptNotResumed) {
  SimOptions sim = SimPreset("demo");
  sim.num_pairs = 5;
  sim.seed = 11;
  const fs::path dir = test::TempDir("capture_follow_foreign");
  SimulateDataset(sim, dir / "capture");
  const fs::path session_path = dir / "capture" / "calibench.session.json";
  for (const bool damaged : {false, true}) {
    Session foreign;
    foreign.dataset = dir / "elsewhere" / "dataset.json";
    foreign.pairs.resize(1);
    foreign.pairs[0].id = "0000";
    foreign.pairs[0].status = PairStatus::kRejected;
    const std::string text = damaged ? std::string("{\"format\": \"calibench.sess")
                                     : SessionToJson(foreign, session_path);
    fs::remove(SessionBackupPath(session_path, 1));
    std::ofstream(session_path) << text;
    Heard heard;
    const CaptureFollowRequest request = FolderRequest(dir / "capture", 0.5);
    std::string why;
    ASSERT_TRUE(FollowCapture(
        request, CalibrationJobOptions{},
        [&](const FollowEvent& e) {
          FollowEvent copy = e;
          copy.advice = nullptr;
          heard.events.push_back(copy);
        },
        &why))
        << why;
    const std::vector<std::string> notes = heard.said("note");
    const std::string kept = SessionBackupPath(session_path, 1).string();
    bool said = false;
    for (const std::string& note : notes)
      said |= note.find(session_path.string()) != std::string::npos &&
              note.find("kept as " + kept) != std::string::npos;
    EXPECT_TRUE(said) << ::testing::PrintToString(notes);
    for (const std::string& resumed : heard.said("resumed"))  // the feature cache may be
      EXPECT_EQ(resumed.find("the session in"), std::string::npos) << resumed;
    EXPECT_EQ(test::ReadFileBytes(kept), text);
    const Session written = LoadSession(session_path);
    EXPECT_EQ(written.dataset, NormalizeSessionPath(dir / "capture"));
    ASSERT_EQ(written.pairs.size(), 5u);
    for (const PairState& pair : written.pairs)  // nothing of the other session's word
      EXPECT_EQ(pair.status, PairStatus::kAccepted) << (damaged ? "damaged: " : "") << pair.id;
  }
}

}  // namespace
}  // namespace calibench
