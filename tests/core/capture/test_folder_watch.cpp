// GrowingFolder: pairs complete when both files are written, once; partners that never come and
// files that go away are reported.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "core/capture/folder_watch.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

void WriteCaptureFile(const fs::path& path, const std::string& bytes, bool append = false) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, append ? std::ios::binary | std::ios::app : std::ios::binary);
  out << bytes;
}

// Backdates a file: written before the watch looked.
void Backdate(const fs::path& path) {
  fs::last_write_time(path, fs::file_time_type::clock::now() - std::chrono::seconds(60));
}

std::vector<std::string> StemsOf(const std::vector<FolderEvent>& events, FolderEvent::Kind kind) {
  std::vector<std::string> stems;
  for (const FolderEvent& e : events)
    if (e.kind == kind) stems.push_back(e.stem);
  return stems;
}

TEST(GrowingFolder, FilesWrittenBeforeTheFirstLookCompleteAtOnceInNaturalOrder) {
  const fs::path dir = test::TempDir("folder_watch_old");
  for (const char* stem : {"pose10", "pose2", "pose1"}) {
    WriteCaptureFile(dir / "clouds" / (std::string(stem) + ".pcd"), "cloud");
    WriteCaptureFile(dir / "images" / (std::string(stem) + ".png"), "image");
    Backdate(dir / "clouds" / (std::string(stem) + ".pcd"));
    Backdate(dir / "images" / (std::string(stem) + ".png"));
  }
  GrowingFolder folder(dir);
  const auto events = folder.Poll(0.0);
  EXPECT_EQ(StemsOf(events, FolderEvent::Kind::kPairComplete),
            (std::vector<std::string>{"pose1", "pose2", "pose10"}));
  EXPECT_EQ(events[0].pair.cloud, dir / "clouds" / "pose1.pcd");
  EXPECT_EQ(events[0].pair.image, dir / "images" / "pose1.png");
  EXPECT_TRUE(folder.Poll(1.0).empty());  // never returned again
}

TEST(GrowingFolder, AFileStillGrowingWaitsUntilItSettles) {
  const fs::path dir = test::TempDir("folder_watch_growing");
  WriteCaptureFile(dir / "images" / "a.png", "image");
  Backdate(dir / "images" / "a.png");
  WriteCaptureFile(dir / "clouds" / "a.pcd", "first half");
  FolderWatchOptions options;
  options.settle_s = 0.3;
  GrowingFolder folder(dir, options);
  EXPECT_TRUE(folder.Poll(0.0).empty());  // just written: not settled
  WriteCaptureFile(dir / "clouds" / "a.pcd", " second half", /*append=*/true);
  EXPECT_TRUE(folder.Poll(0.2).empty());
  EXPECT_TRUE(folder.Poll(0.4).empty());  // changed at 0.2: settles at 0.5
  EXPECT_EQ(StemsOf(folder.Poll(0.6), FolderEvent::Kind::kPairComplete),
            std::vector<std::string>{"a"});
}

TEST(GrowingFolder, AFileRenamedFromItsTemporaryNameIsCompleteAtOnce) {
  const fs::path dir = test::TempDir("folder_watch_rename");
  WriteCaptureFile(dir / "images" / "b.png", "image");
  Backdate(dir / "images" / "b.png");
  WriteCaptureFile(dir / "clouds" / "b.pcd.part", "cloud being written");
  FolderWatchOptions options;
  options.settle_s = 5.0;  // far longer than the test: only the rename can complete it
  GrowingFolder folder(dir, options);
  EXPECT_TRUE(folder.Poll(0.0).empty());
  fs::rename(dir / "clouds" / "b.pcd.part", dir / "clouds" / "b.pcd");
  EXPECT_EQ(StemsOf(folder.Poll(0.1), FolderEvent::Kind::kPairComplete),
            std::vector<std::string>{"b"});
  EXPECT_TRUE(IsTemporaryFileName("x.pcd.part"));
  EXPECT_TRUE(IsTemporaryFileName(".x.png"));
  EXPECT_FALSE(IsTemporaryFileName("pose1.pcd"));
}

TEST(GrowingFolder, AMissingPartnerIsReportedOnceAndTheRemovalOfAFileToo) {
  const fs::path dir = test::TempDir("folder_watch_partner");
  WriteCaptureFile(dir / "clouds" / "c.pcd", "cloud");
  Backdate(dir / "clouds" / "c.pcd");
  WriteCaptureFile(dir / "images" / "d.png", "image");
  Backdate(dir / "images" / "d.png");
  FolderWatchOptions options;
  options.partner_timeout_s = 10.0;
  GrowingFolder folder(dir, options);
  EXPECT_TRUE(folder.Poll(0.0).empty());
  const auto late = folder.Poll(10.5);
  ASSERT_EQ(StemsOf(late, FolderEvent::Kind::kIncomplete), (std::vector<std::string>{"c", "d"}));
  EXPECT_NE(late[0].reason.find("c.pcd has no image after 10 s"), std::string::npos)
      << late[0].reason;
  EXPECT_NE(late[1].reason.find("d.png has no cloud"), std::string::npos) << late[1].reason;
  EXPECT_TRUE(folder.Poll(11.0).empty());  // once
  // The partner arrives after all: the pair completes.
  WriteCaptureFile(dir / "images" / "c.png", "image");
  Backdate(dir / "images" / "c.png");
  EXPECT_EQ(StemsOf(folder.Poll(12.0), FolderEvent::Kind::kPairComplete),
            std::vector<std::string>{"c"});
  fs::remove(dir / "images" / "d.png");
  const auto removed = folder.Poll(13.0);
  ASSERT_EQ(StemsOf(removed, FolderEvent::Kind::kRemoved), std::vector<std::string>{"d"});
  EXPECT_NE(removed[0].reason.find("d.png was removed while watched"), std::string::npos);
}

TEST(GrowingFolder, AFolderWithoutItsSubfoldersYetIsAnEmptyCapture) {
  const fs::path dir = test::TempDir("folder_watch_empty");
  GrowingFolder folder(dir);
  EXPECT_TRUE(folder.Poll(0.0).empty());
  FolderWatchOptions bad;
  bad.partner_timeout_s = 0;
  std::string why;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("partner_timeout_s"), std::string::npos);
}

}  // namespace
}  // namespace calibench
