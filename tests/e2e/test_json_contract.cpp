// The machine output contract of every command that has one (`advise --json`, `watch
// --json-lines`): stdout holds exactly the documented objects, whatever the libraries underneath
// print. A board small in the image makes OpenCV's estimateChessboardSharpness print
// "calcEdgeSharpness: checkerboard too small for calculation." on stdout; it must land on stderr.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kOpenCvChatter = "calcEdgeSharpness";

struct Streams {
  int code = 0;
  std::string out, err;
};

// Runs `command` with stdout and stderr in files of their own.
Streams RunSplit(const std::string& command, const fs::path& dir, const std::string& name) {
  const fs::path out = dir / (name + ".stdout"), err = dir / (name + ".stderr");
  std::string ignored;
  Streams streams;
  streams.code =
      test::RunCommand("(" + command + " >" + out.string() + " 2>" + err.string() + ")", &ignored);
  streams.out = test::ReadFileBytes(out);
  streams.err = test::ReadFileBytes(err);
  return streams;
}

// A VLP-16 + A3 checkerboard set whose farthest boards are small in an 800x600 image (squares
// of a few pixels at 12 m: OpenCV cannot measure their edges and says so).
fs::path FarBoardSet(const std::string& name) {
  const fs::path dir = test::TempDir(name + "_" + std::to_string(getpid()));
  const int code =
      test::RunCommand(test::CalibenchExe() + " simulate --out " + (dir / "sim").string() +
                       " --lidar vlp16 --board a3 --pairs 10 --image-size 800x600 "
                       "--min-distance 2 --max-distance 12 --seed 7 >/dev/null 2>&1");
  EXPECT_EQ(code, 0);
  return dir;
}

TEST(JsonContract, AdviseJsonIsOneObjectWhileOpenCvTalks) {
  const fs::path dir = FarBoardSet("json_contract_advise");
  const Streams s = RunSplit(
      test::CalibenchExe() + " advise --dataset " + (dir / "sim").string() + " --json --threads 2",
      dir, "advise");
  ASSERT_EQ(s.code, 0) << s.err;
  // The library did talk (else this test would prove nothing), and not on stdout.
  EXPECT_NE(s.err.find(kOpenCvChatter), std::string::npos) << s.err;
  EXPECT_EQ(s.out.find(kOpenCvChatter), std::string::npos) << s.out;
  // Exactly one JSON object and its newline: nothing before, nothing after.
  ASSERT_FALSE(s.out.empty());
  EXPECT_EQ(s.out.front(), '{') << s.out;
  EXPECT_EQ(s.out.find('\n'), s.out.size() - 1) << s.out;
  json advice;
  ASSERT_NO_THROW(advice = json::parse(s.out)) << s.out;
  ASSERT_TRUE(advice.is_object());
  for (const char* field : {"pairs_used", "cam_from_lidar", "sigma_t_mm", "sigma_r_deg", "goal",
                            "done", "next", "pairs"})
    EXPECT_TRUE(advice.contains(field)) << field;
}

TEST(JsonContract, WatchJsonLinesAreEventsOnlyWhileOpenCvTalks) {
  const fs::path dir = FarBoardSet("json_contract_watch");
  const Streams s = RunSplit(test::CalibenchExe() + " watch " + (dir / "sim").string() +
                                 " --json-lines --idle-exit 2 --threads 2",
                             dir, "watch");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.err.find(kOpenCvChatter), std::string::npos) << s.err;
  std::istringstream lines(s.out);
  std::string line;
  int events = 0, pairs = 0, solves = 0;
  while (std::getline(lines, line)) {
    json event;
    ASSERT_NO_THROW(event = json::parse(line)) << "not JSON on stdout: " << line;
    ASSERT_TRUE(event.is_object()) << line;
    ASSERT_TRUE(event.contains("event")) << line;
    EXPECT_TRUE(event.at("time").is_number()) << line;
    ++events;
    pairs += event.at("event") == "pair";
    solves += event.at("event") == "solve";
  }
  EXPECT_EQ(pairs, 10) << s.out;
  EXPECT_GE(solves, 1) << s.out;
  EXPECT_GT(events, pairs);
}

}  // namespace
}  // namespace calibench
