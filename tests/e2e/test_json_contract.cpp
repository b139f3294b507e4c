// The machine output contract of every command that has one (`advise --json`, `watch
// --json-lines`): stdout holds exactly the documented objects, whatever the libraries underneath
// print. MachineStdout (app/machine_stdout.h) points file descriptor 1 at stderr while a command
// runs: tested here with chatter of our own on both C and C++ streams. And the chatter users met
// first is gone at its source: a board small in the image made OpenCV's
// estimateChessboardSharpness print "calcEdgeSharpness: checkerboard too small for calculation."
// on stdout; the sharpness is now asked for only where OpenCV can measure it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/machine_stdout.h"
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
// of a few pixels at 12 m: OpenCV cannot measure their edges).
fs::path FarBoardSet(const std::string& name) {
  const fs::path dir = test::TempDir(name + "_" + std::to_string(getpid()));
  const int code =
      test::RunCommand(test::CalibenchExe() + " simulate --out " + (dir / "sim").string() +
                       " --lidar vlp16 --board a3 --pairs 10 --image-size 800x600 "
                       "--min-distance 2 --max-distance 12 --seed 7 >/dev/null 2>&1");
  EXPECT_EQ(code, 0);
  return dir;
}

TEST(JsonContract, AdviseJsonIsOneObjectOnBoardsTooSmallToMeasure) {
  const fs::path dir = FarBoardSet("json_contract_advise");
  const Streams s = RunSplit(
      test::CalibenchExe() + " advise --dataset " + (dir / "sim").string() + " --json --threads 2",
      dir, "advise");
  ASSERT_EQ(s.code, 0) << s.err;
  // OpenCV was not asked what it cannot measure: it said nothing, on either stream.
  EXPECT_EQ(s.err.find(kOpenCvChatter), std::string::npos) << s.err;
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

TEST(JsonContract, WatchJsonLinesAreEventsOnlyOnBoardsTooSmallToMeasure) {
  const fs::path dir = FarBoardSet("json_contract_watch");
  const Streams s = RunSplit(test::CalibenchExe() + " watch " + (dir / "sim").string() +
                                 " --json-lines --idle-exit 2 --threads 2",
                             dir, "watch");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_EQ(s.err.find(kOpenCvChatter), std::string::npos) << s.err;
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

// The mechanism itself, in this process: while a MachineStdout is active, what anything writes to
// stdout (printf, std::cout, a raw write on descriptor 1) reaches stderr, and only Print reaches
// the real stdout; afterwards stdout is itself again.
TEST(JsonContract, MachineStdoutSendsWhatLibrariesPrintToStderr) {
  const fs::path dir = test::TempDir("json_contract_machine_stdout_" + std::to_string(getpid()));
  const fs::path out_file = dir / "stdout", err_file = dir / "stderr";
  std::fflush(stdout);
  std::fflush(stderr);
  const int saved_out = ::dup(STDOUT_FILENO), saved_err = ::dup(STDERR_FILENO);
  ASSERT_GE(saved_out, 0);
  ASSERT_GE(saved_err, 0);
  std::FILE* out = std::fopen(out_file.c_str(), "w");
  std::FILE* err = std::fopen(err_file.c_str(), "w");
  ASSERT_TRUE(out && err);
  ::dup2(::fileno(out), STDOUT_FILENO);
  ::dup2(::fileno(err), STDERR_FILENO);
  {
    app::MachineStdout machine(true);
    std::printf("printf chatter\n");
    machine.Print(R"({"first":1})");
    std::cout << "cout chatter" << std::endl;
    const char raw[] = "raw chatter\n";
    EXPECT_EQ(::write(STDOUT_FILENO, raw, sizeof(raw) - 1), static_cast<ssize_t>(sizeof(raw) - 1));
    machine.Print(R"({"second":2})");
  }
  std::printf("after\n");
  std::fflush(stdout);
  ::dup2(saved_out, STDOUT_FILENO);
  ::dup2(saved_err, STDERR_FILENO);
  ::close(saved_out);
  ::close(saved_err);
  std::fclose(out);
  std::fclose(err);
  EXPECT_EQ(test::ReadFileBytes(out_file), "{\"first\":1}\n{\"second\":2}\nafter\n");
  EXPECT_EQ(test::ReadFileBytes(err_file), "printf chatter\ncout chatter\nraw chatter\n");
}

}  // namespace
}  // namespace calibench
