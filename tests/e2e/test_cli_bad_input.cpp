// Bad input through the real executable: every case gets a message that names the file and the
// problem, and a non-zero exit code; nothing crashes and no made-up result is printed.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/base/image.h"
#include "core/io/image_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

class CliBadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ctest runs each test in its own process, possibly in parallel: one folder per process.
    dir_ = new fs::path(test::TempDir("cli_bad_input_" + std::to_string(getpid())));
    SimOptions sim = SimPreset("default");
    sim.num_pairs = 5;
    sim.seed = 5;
    SimulateDataset(sim, *dir_ / "good");
  }
  static void TearDownTestSuite() { delete dir_; }

  static json Manifest() {
    std::ifstream in(*dir_ / "good/dataset.json");
    json j = json::parse(in);
    for (auto& p : j["pairs"]) {  // absolute paths, so that edited copies can live elsewhere
      p["cloud"] = (*dir_ / "good" / p["cloud"].get<std::string>()).string();
      p["image"] = (*dir_ / "good" / p["image"].get<std::string>()).string();
    }
    return j;
  }
  static fs::path Write(const std::string& name, const json& manifest) {
    const fs::path path = *dir_ / (name + ".json");
    std::ofstream(path) << manifest.dump(2);
    return path;
  }
  static int Calibrate(const fs::path& manifest, std::string* output,
                       const std::string& extra = "") {
    return test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + manifest.string() +
                                " --out " + (*dir_ / "result.json").string() + " " + extra,
                            output);
  }
  static fs::path* dir_;
};
fs::path* CliBadInput::dir_ = nullptr;

TEST_F(CliBadInput, GoodDatasetCalibrates) {
  std::string out;
  EXPECT_EQ(Calibrate(*dir_ / "good/dataset.json", &out), 0) << out;
  EXPECT_NE(out.find("cam_from_lidar"), std::string::npos);
  EXPECT_NE(out.find("maps points from the lidar frame into the cam frame"), std::string::npos);
}

TEST_F(CliBadInput, MissingManifest) {
  std::string out;
  EXPECT_EQ(Calibrate(*dir_ / "nope.json", &out), 2);
  EXPECT_NE(out.find("nope.json"), std::string::npos) << out;
  EXPECT_NE(out.find("no such file"), std::string::npos) << out;
}

TEST_F(CliBadInput, ManifestThatIsNotJson) {
  const fs::path path = *dir_ / "garbage.json";
  std::ofstream(path) << "{ this is not json";
  std::string out;
  EXPECT_EQ(Calibrate(path, &out), 2);
  EXPECT_NE(out.find("garbage.json"), std::string::npos) << out;
  EXPECT_NE(out.find("not valid JSON"), std::string::npos) << out;
}

TEST_F(CliBadInput, WrongDistortionCountForTheModel) {
  json m = Manifest();
  m["camera"]["model"] = "kannala-brandt";
  m["camera"]["distortion"] = {0.1, 0.01, 0.0, 0.0, 0.0};
  std::string out;
  EXPECT_EQ(Calibrate(Write("fisheye5", m), &out), 2);
  EXPECT_NE(out.find("fisheye5.json"), std::string::npos) << out;
  EXPECT_NE(out.find("4"), std::string::npos) << out;
}

TEST_F(CliBadInput, UnreadableAndCorruptCloudsFailTheirPairsAndAreNamed) {
  json m = Manifest();
  // Truncated binary PCD.
  const fs::path truncated = *dir_ / "truncated.pcd";
  {
    std::ifstream in(m["pairs"][0]["cloud"].get<std::string>(), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  m["pairs"][0]["cloud"] = truncated.string();
  // A cloud without z.
  const fs::path no_z = *dir_ / "no_z.pcd";
  std::ofstream(no_z) << "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\n"
                         "HEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n";
  m["pairs"][1]["cloud"] = no_z.string();
  std::string out;
  EXPECT_EQ(Calibrate(Write("bad_clouds", m), &out), 2);
  EXPECT_NE(out.find("truncated.pcd"), std::string::npos) << out;
  EXPECT_NE(out.find("no_z.pcd"), std::string::npos) << out;
  // The remaining three pairs still calibrate and the result is written.
  EXPECT_NE(out.find("cam_from_lidar"), std::string::npos) << out;
}

// A cloud path that is a FIFO (read, it would block forever) and one that is a loop of symbolic
// links: each fails its own pair with the file named; the others calibrate.
TEST_F(CliBadInput, FifoAndLinkLoopCloudsFailTheirPairsWithoutHanging) {
  json m = Manifest();
  const fs::path fifo = *dir_ / "fifo.pcd";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  m["pairs"][0]["cloud"] = fifo.string();
  const fs::path loop = *dir_ / "loop.pcd", other = *dir_ / "loop2.pcd";
  fs::remove(loop);
  fs::remove(other);
  fs::create_symlink(other, loop);
  fs::create_symlink(loop, other);
  m["pairs"][1]["cloud"] = loop.string();
  std::string out;
  EXPECT_EQ(Calibrate(Write("special_files", m), &out), 2);
  EXPECT_NE(out.find(fifo.string() + ": is not a regular file"), std::string::npos) << out;
  EXPECT_NE(out.find(loop.string() + ": cannot read: Too many levels of symbolic links"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("cam_from_lidar"), std::string::npos) << out;
}

TEST_F(CliBadInput, MissingImageAndAnImageWithoutABoard) {
  json m = Manifest();
  m["pairs"][0]["image"] = (*dir_ / "missing.png").string();
  std::string out;
  EXPECT_EQ(Calibrate(Write("missing_image", m), &out), 2);
  EXPECT_NE(out.find("missing.png"), std::string::npos) << out;

  // A blank image of the right size: that pair fails with a reason, the rest go on (exit 0).
  json blank = Manifest();
  const std::string blank_png = (*dir_ / "blank.png").string();
  ASSERT_EQ(
      test::RunCommand("cp " + blank["pairs"][0]["image"].get<std::string>() + " " + blank_png), 0);
  ImageU8 image = LoadImage(blank_png);
  std::fill(image.data.begin(), image.data.end(), 128);
  SaveImage(blank_png, image);
  blank["pairs"][0]["image"] = blank_png;
  EXPECT_EQ(Calibrate(Write("blank_image", blank), &out), 0) << out;
  EXPECT_NE(out.find("failed: camera:"), std::string::npos) << out;
}

TEST_F(CliBadInput, SeedThatHitsNoPlane) {
  json m = Manifest();
  m["pairs"][0]["lidar_seed"]["point"] = {50.0, 50.0, 50.0};
  std::string out;
  EXPECT_EQ(Calibrate(Write("empty_seed", m), &out), 0) << out;
  EXPECT_NE(out.find("holds no points"), std::string::npos) << out;
}

TEST_F(CliBadInput, FewerThanThreeUsablePairs) {
  json m = Manifest();
  m["pairs"] = json::array({m["pairs"][0], m["pairs"][1]});
  std::string out;
  EXPECT_EQ(Calibrate(Write("two_pairs", m), &out), 3);
  EXPECT_NE(out.find("only 2 usable pair"), std::string::npos) << out;
  EXPECT_EQ(out.find("[ "), std::string::npos) << "no matrix may be printed:\n" << out;
}

TEST_F(CliBadInput, DegenerateGeometryIsReportedWithTheWeakDirection) {
  json m = Manifest();
  json same = json::array();
  for (int i = 0; i < 4; ++i) {  // the same board pose four times: all normals parallel
    json p = m["pairs"][0];
    p["id"] = "copy" + std::to_string(i);
    same.push_back(p);
  }
  m["pairs"] = same;
  std::string out;
  EXPECT_EQ(Calibrate(Write("parallel", m), &out), 3);
  EXPECT_NE(out.find("parallel"), std::string::npos) << out;
  // With a user guess the solver runs, and says what the data cannot fix.
  const auto& gt = m["ground_truth"]["cam_from_lidar"];
  std::string guess;
  for (const auto& row : gt)
    for (const auto& v : row) guess += (guess.empty() ? "" : ",") + std::to_string(v.get<double>());
  EXPECT_EQ(Calibrate(Write("parallel", m), &out, "--initial-guess " + guess), 4) << out;
  EXPECT_NE(out.find("NOT well constrained"), std::string::npos) << out;
  EXPECT_NE(out.find("translation along camera"), std::string::npos) << out;
}

TEST_F(CliBadInput, BadFlags) {
  std::string out;
  EXPECT_EQ(Calibrate(*dir_ / "good/dataset.json", &out, "--huber-delta -1"), 1);
  EXPECT_NE(out.find("huber_delta"), std::string::npos) << out;
  EXPECT_EQ(Calibrate(*dir_ / "good/dataset.json", &out, "--lidar-model cone"), 1);
  EXPECT_NE(
      out.find("--lidar-model must be one of spinning, swept, non-repetitive, segment, not 'cone'"),
      std::string::npos)
      << out;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " frobnicate", &out), 1);
}

}  // namespace
}  // namespace calibench
