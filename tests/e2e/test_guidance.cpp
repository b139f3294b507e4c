// Guided capture end to end: σ honest at small k on the real ACFR set, `advise` on it and on a
// simulated set (the JSON contract), and the guided-vs-random protocol on a small simulation.
#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/estimation/uncertainty.h"
#include "core/evaluation/guided_sweep.h"
#include "core/evaluation/subset_coverage.h"
#include "core/guidance/detection_reach.h"
#include "core/guidance/next_pose.h"
#include "core/io/dataset.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

using nlohmann::json;

Mat4 MatrixFrom(const json& rows) {
  Mat4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  return m;
}

// The advise --json contract: exactly one JSON object on stdout with these fields and types.
json ExpectAdviceContract(const std::string& stdout_text) {
  json advice;
  EXPECT_NO_THROW(advice = json::parse(stdout_text)) << stdout_text;
  EXPECT_TRUE(advice.is_object());
  EXPECT_TRUE(advice.at("pairs_used").is_number_integer());
  EXPECT_TRUE(advice.at("cam_from_lidar").is_array());
  EXPECT_EQ(advice.at("cam_from_lidar").size(), 4u);
  for (const json& row : advice.at("cam_from_lidar")) EXPECT_EQ(row.size(), 4u);
  EXPECT_EQ(advice.at("sigma_t_mm").size(), 3u);
  EXPECT_EQ(advice.at("sigma_r_deg").size(), 3u);
  EXPECT_TRUE(advice.at("goal").at("t_mm").is_number());
  EXPECT_TRUE(advice.at("goal").at("r_deg").is_number());
  EXPECT_TRUE(advice.at("done").is_boolean());
  EXPECT_TRUE(advice.at("next").is_null() || advice.at("next").is_object());
  EXPECT_EQ(advice.at("done").get<bool>(), advice.at("next").is_null());
  const json& reach = advice.at("detection_reach");
  for (const char* key : {"min_square_px", "max_incidence_deg", "max_off_axis_deg"})
    EXPECT_TRUE(reach.at(key).is_null() || reach.at(key).is_number()) << key;
  EXPECT_TRUE(reach.at("boards_found").is_number_integer());
  EXPECT_TRUE(reach.at("boards_missed").is_number_integer());
  if (advice.at("next").is_object()) {
    const json& tolerance = advice.at("next").at("tolerance");
    EXPECT_TRUE(tolerance.at("translation_m").is_number());
    EXPECT_TRUE(tolerance.at("rotation_deg").is_number());
    EXPECT_TRUE(tolerance.at("usable_share").is_number());
    EXPECT_TRUE(tolerance.at("words").is_string());
    EXPECT_TRUE(advice.at("next").at("usable_share").is_number());
  }
  return advice;
}

// The command's standard output alone (its progress on stderr is dropped).
std::string StdoutOf(const std::string& command, int* code) {
  // One file per process and call: ctest runs the tests of this file side by side.
  static int calls = 0;
  const auto file =
      test::TempDir("guidance_stdout_" + std::to_string(getpid()) + "_" + std::to_string(calls++)) /
      "stdout.txt";
  std::string ignored;
  // In a subshell: RunCommand appends 2>&1, which must not reach the file.
  *code = test::RunCommand("(" + command + " >" + file.string() + " 2>/dev/null)", &ignored);
  return test::ReadFileBytes(file);
}

TEST(GuidanceReal, SigmaIsHonestAtSmallK) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const Dataset folder = LoadDataset(test::WriteAcfrFolder(
      shared / "datasets/acfr-vlp16-chessboard", test::TempDir("guidance_acfr_sigma")));
  PipelineOptions options;
  options.threads = 2;
  const CalibrationOutcome all = CalibrateDataset(folder, options);
  ASSERT_TRUE(all.solution) << all.failure;
  SubsetCoverageOptions coverage;  // first k = 4..30 and 5 random subsets of each size
  const SubsetCoverage result = RunSubsetCoverage(all.pairs, options, coverage);
  std::printf("%s", FormatSubsetCoverage(result, coverage.coverage_sigmas).c_str());
  const int cases = static_cast<int>(result.cases.size());
  ASSERT_EQ(cases, 7 + 7 * 5);
  EXPECT_EQ(result.solved, cases);
  // The bar: within 3σ on every axis in at least 90 % of the cases.
  EXPECT_GE(result.covered, static_cast<int>(std::ceil(0.9 * cases)));
  // Honest, not merely wide: at 30 pairs σ stays within a few mm and a tenth of a degree.
  for (const SubsetCase& c : result.cases) {
    if (c.k != 30) continue;
    EXPECT_LT(c.sigma_t_m.maxCoeff(), 0.010) << c.kind;
    EXPECT_LT(c.sigma_r_deg.maxCoeff(), 0.25) << c.kind;
  }
}

TEST(GuidanceReal, AdviseOnTheAcfrFolderSuggestsAPoseTheSimulatorCanHold) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto folder = test::WriteAcfrFolder(shared / "datasets/acfr-vlp16-chessboard",
                                            test::TempDir("guidance_acfr_advise"));
  int code = 0;
  // A goal the 40 pairs do not reach: the next pose is asked for.
  const std::string out = StdoutOf(test::CalibenchExe() + " advise --dataset " + folder.string() +
                                       " --json --goal-mm 1 --goal-deg 0.02 --threads 2",
                                   &code);
  ASSERT_EQ(code, 0) << out;
  const json advice = ExpectAdviceContract(out);
  EXPECT_GE(advice.at("pairs_used").get<int>(), 36);
  EXPECT_FALSE(advice.at("done").get<bool>());
  const json& next = advice.at("next");
  ASSERT_TRUE(next.is_object());
  const std::string words = next.at("words").get<std::string>();
  std::printf("advise on ACFR: %s\n", words.c_str());
  EXPECT_NE(words.find(" m away"), std::string::npos);
  EXPECT_NE(words.find("of the image"), std::string::npos);
  // The suggested pose, held in the simulator with the ACFR camera, the VLP-16 and this board:
  // the sheet inside the image and at least 4 rings on it.
  const Dataset dataset = LoadDataset(folder);
  const Pose cam_from_lidar(MatrixFrom(advice.at("cam_from_lidar")));
  const Pose lidar_from_shown(MatrixFrom(next.at("lidar_from_board")));
  const Pose cam_from_board = cam_from_lidar * lidar_from_shown * ShownFromBoardSpec().inverse();
  SensorGeometry sensors;
  sensors.camera = dataset.camera;
  sensors.board = dataset.target;
  sensors.lidar = MakeBeamTable(LidarModel::kVlp16);
  sensors.min_distance_m = 0.5;
  sensors.max_distance_m = 10.0;
  const Feasibility f = CheckFeasible(sensors, cam_from_lidar, cam_from_board, GuidanceOptions{});
  EXPECT_TRUE(f.feasible) << f.why;
  LidarScene scene;
  scene.lidar_from_board = cam_from_lidar.inverse() * cam_from_board;
  scene.clutter = false;
  const LidarScan scan =
      SimulateLidarScan(sensors.lidar, BoardPrint(dataset.target), scene, LidarScanOptions{});
  std::vector<int> per_ring(16, 0);
  for (int ring : scan.ring) ++per_ring[ring];
  const int rings = static_cast<int>(
      std::count_if(per_ring.begin(), per_ring.end(), [](int n) { return n >= 3; }));
  std::printf("suggested pose in the simulator: %d rings, %zu points on the sheet\n", rings,
              scan.size());
  EXPECT_GE(rings, 4);

  // A goal the pairs reach: done, no next pose.
  const std::string done_out = StdoutOf(test::CalibenchExe() + " advise --dataset " +
                                            folder.string() + " --json --goal-mm 50 --goal-deg 1",
                                        &code);
  ASSERT_EQ(code, 0);
  const json done = ExpectAdviceContract(done_out);
  EXPECT_TRUE(done.at("done").get<bool>());
}

TEST(GuidanceCli, AdviseJsonOnASimulatedDatasetAndItsWords) {
  const auto dir = test::TempDir("guidance_cli");
  int code = test::RunCommand(test::CalibenchExe() + " simulate --out " + (dir / "sim").string() +
                              " --pairs 5 --seed 3 >/dev/null 2>&1");
  ASSERT_EQ(code, 0);
  const std::string manifest = (dir / "sim/dataset.json").string();
  const std::string out = StdoutOf(
      test::CalibenchExe() + " advise --dataset " + manifest + " --json --threads 2", &code);
  ASSERT_EQ(code, 0) << out;
  const json advice = ExpectAdviceContract(out);
  EXPECT_EQ(advice.at("pairs_used").get<int>(), 5);
  // Five pairs: under the stop rule's minimum, so not done whatever σ says.
  EXPECT_FALSE(advice.at("done").get<bool>());
  EXPECT_FALSE(advice.at("trustworthy").get<bool>());
  ASSERT_TRUE(advice.at("next").is_object());
  EXPECT_EQ(advice.at("next").at("lidar_from_board").size(), 4u);
  EXPECT_EQ(advice.at("pairs").size(), 5u);
  for (const json& p : advice.at("pairs")) {
    EXPECT_TRUE(p.at("name").is_string());
    EXPECT_TRUE(p.at("findings").is_array());
  }
  // The people's form says the same.
  std::string text;
  text = StdoutOf(test::CalibenchExe() + " advise --dataset " + manifest + " --threads 2", &code);
  ASSERT_EQ(code, 0);
  EXPECT_NE(text.find("5 pairs: σ"), std::string::npos) << text;
  EXPECT_NE(text.find("next pose: about"), std::string::npos) << text;
  // Bad input: a clear message naming the file, a non-zero exit.
  std::string bad;
  code = test::RunCommand(test::CalibenchExe() + " advise --dataset " + (dir / "nothing").string(),
                          &bad);
  EXPECT_NE(code, 0);
  EXPECT_NE(bad.find((dir / "nothing").string()), std::string::npos) << bad;
  code = test::RunCommand(test::CalibenchExe() + " advise --dataset " + manifest + " --goal-mm 0",
                          &bad);
  EXPECT_NE(code, 0);
  EXPECT_NE(bad.find("goal must be > 0"), std::string::npos) << bad;
}

// A fisheye of 848 × 800 with an A3 ChArUco at 1-2 m: the detector misses the far and steep boards
// of random placement. `advise` says why for each miss the LiDAR places, learns the reach from
// them, and suggests a pose inside it with its tolerance; `--hand-tolerance-*` are taken.
TEST(GuidanceCli, AdviseSaysWhyTheCameraMissedABoardAndKeepsInsideTheReach) {
  const auto dir = test::TempDir("guidance_reach");
  int code = test::RunCommand(test::CalibenchExe() + " simulate --out " + (dir / "sim").string() +
                              " --lidar os0-128 --camera fisheye --board charuco-a3 --image-size "
                              "848x800 --min-distance 1.0 --max-distance 2.0 --pairs 12 --seed 3 "
                              ">/dev/null 2>&1");
  ASSERT_EQ(code, 0);
  const std::string manifest = (dir / "sim/dataset.json").string();
  const std::string out =
      StdoutOf(test::CalibenchExe() + " advise --dataset " + manifest +
                   " --json --threads 2 --goal-mm 0.3 --goal-deg 0.02 --hand-tolerance-m 0.08",
               &code);
  ASSERT_EQ(code, 0) << out;
  const json advice = ExpectAdviceContract(out);
  int told = 0;
  for (const json& p : advice.at("pairs"))
    for (const json& f : p.at("findings"))
      if (f.at("check") == "reach") {
        ++told;
        EXPECT_EQ(p.at("status"), "failed") << p.dump();
        const std::string words = f.at("words");
        EXPECT_TRUE(words.find("board too small in the image at") != std::string::npos ||
                    words.find("the camera missed the board at") != std::string::npos)
            << words;
      }
  const json& reach = advice.at("detection_reach");
  EXPECT_EQ(told, reach.at("boards_missed").get<int>());
  EXPECT_GE(told, 3);  // of 12 random boards, 5 are missed (4 too small)
  ASSERT_TRUE(reach.at("min_square_px").is_number());
  ASSERT_TRUE(advice.at("next").is_object());
  const json& tolerance = advice.at("next").at("tolerance");
  EXPECT_LE(tolerance.at("translation_m").get<double>(), 0.08 + 1e-12);
  EXPECT_GE(tolerance.at("usable_share").get<double>(), 0.9);
  // The suggested pose keeps inside the learnt reach, with the suggestions' margin.
  Dataset dataset = LoadDataset(manifest);
  Pose cam_from_board;
  cam_from_board.matrix() = MatrixFrom(advice.at("next").at("cam_from_board"));
  const double square_px =
      AppearanceOf(dataset.camera, dataset.target, cam_from_board * ShownFromBoardSpec().inverse())
          .square_px;
  EXPECT_GE(square_px, 1.25 * reach.at("min_square_px").get<double>()) << out;
}

TEST(GuidanceCli, TheLrfMeterFollowsAlgorithmOne) {
  const auto dir = test::TempDir("guidance_lrf");
  int code =
      test::RunCommand(test::CalibenchExe() + " simulate --kind lrf --observations 12 --out " +
                       (dir / "lrf").string() + " >/dev/null 2>&1");
  ASSERT_EQ(code, 0);
  const std::string manifest = (dir / "lrf/manifest.json").string();
  // A loose goal and threshold: Algorithm 1 stops early and the meter says done.
  std::string out = StdoutOf(test::CalibenchExe() + " advise --dataset " + manifest +
                                 " --json --goal-mm 50 --goal-deg 2 --error-threshold-mm 20",
                             &code);
  ASSERT_EQ(code, 0) << out;
  json advice = json::parse(out);
  ASSERT_EQ(advice.at("cam_from_lrf").size(), 4u);
  EXPECT_TRUE(advice.at("adaptive").at("reached").get<bool>());
  EXPECT_LT(advice.at("adaptive").at("newest_error_m").get<double>(), 0.020);
  const int used = advice.at("pairs_used").get<int>();
  EXPECT_GE(used, 3);
  EXPECT_LE(used, 12);
  EXPECT_EQ(advice.at("done").get<bool>(), used >= 4);  // Algorithm 1 stands in for the jackknife
  EXPECT_TRUE(advice.at("next").is_null());
  // A threshold no observation meets: σ is not final, whatever the goal.
  out = StdoutOf(test::CalibenchExe() + " advise --dataset " + manifest +
                     " --json --goal-mm 50 --goal-deg 2 --error-threshold-mm 0.001",
                 &code);
  ASSERT_EQ(code, 0) << out;
  advice = json::parse(out);
  EXPECT_FALSE(advice.at("adaptive").at("reached").get<bool>());
  EXPECT_FALSE(advice.at("done").get<bool>());
  EXPECT_NE(advice.at("trust_note").get<std::string>().find("Algorithm 1"), std::string::npos)
      << out;
  EXPECT_NE(advice.at("next_failure").get<std::string>().find("three-face"), std::string::npos);
}

TEST(GuidanceSweep, GuidedCaptureStopsWithAnHonestResult) {
  // Two captures each way, VLP-16 + A3, with a goal that takes random placement dozens of
  // poses: the protocol runs end to end, guided placement is done with fewer poses, and what it
  // says at "done" is true.
  GuidedSweepOptions options;
  options.sim.lidar = LidarModel::kVlp16;
  options.sim.lidar_range_noise_m = 0.01;
  options.goal = CaptureGoal{0.6, 0.02};
  options.seeds = 2;
  options.max_pairs = 80;
  options.threads = 2;
  const GuidedSweepResult result = RunGuidedSweep(options);
  ASSERT_EQ(result.runs.size(), 4u);
  std::printf("%s", FormatGuidedSweepTable(result).c_str());
  int guided_poses = 0, random_poses = 0;
  for (const GuidedRun& run : result.runs) {
    ASSERT_TRUE(run.done) << run.placement << " seed " << run.seed;
    EXPECT_TRUE(run.within_goal) << run.placement << " seed " << run.seed;
    EXPECT_TRUE(run.within_sigma) << run.placement << " seed " << run.seed;
    (run.placement == "guided" ? guided_poses : random_poses) += run.poses;
  }
  EXPECT_LT(guided_poses, random_poses);
}

// The rig where a hand's error loses pairs: OS0-128, a fisheye of 848 × 800 and an A3 ChArUco at
// 1-2 m, each guided board moved by up to ±10 cm and 10°. Guided placement keeps the boards inside
// what the detector reads (few lost) and needs fewer poses than random placement.
TEST(GuidanceSweep, OnAFisheyeChArUcoRigTheHandLosesFewPairs) {
  GuidedSweepOptions options;
  options.sim.lidar = LidarModel::kOs0_128;
  options.sim.fisheye = true;
  // The default fisheye, its focal length scaled with the width (as `--image-size 848x800`).
  CameraModel camera = DefaultSimCamera(/*fisheye=*/true);
  const double scale = 848.0 / camera.width;
  camera.fx *= scale;
  camera.fy *= scale;
  camera.cx = 0.5 * (848 - 1);
  camera.cy = 0.5 * (800 - 1);
  camera.width = 848;
  camera.height = 800;
  options.sim.camera = camera;
  options.sim.board = BoardPreset("charuco-a3");
  options.sim.min_distance_m = 1.0;
  options.sim.max_distance_m = 2.0;
  options.sim.lidar_range_noise_m = 0.01;
  options.goal = CaptureGoal{0.5, 0.03};
  options.seeds = 2;
  options.max_pairs = 60;
  options.threads = 2;
  const GuidedSweepResult result = RunGuidedSweep(options);
  std::printf("%s", FormatGuidedSweepTable(result).c_str());
  int guided_poses = 0, guided_lost = 0, random_poses = 0;
  for (const GuidedRun& run : result.runs) {
    if (run.placement == "guided") {
      ASSERT_TRUE(run.done) << "seed " << run.seed;
      EXPECT_TRUE(run.within_goal) << "seed " << run.seed;
      guided_poses += run.poses;
      guided_lost += run.poses - run.accepted;
    } else {
      random_poses += run.done ? run.poses : options.max_pairs + 1;
    }
  }
  EXPECT_LE(guided_lost, 0.15 * guided_poses);
  EXPECT_LT(2 * guided_poses, random_poses);
}

}  // namespace
}  // namespace calibench
