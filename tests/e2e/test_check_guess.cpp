// `calibench check --guess` on real road frames (../shared/datasets/opencalib-pandar64-scenes,
// rig-b): a pose typed as a URDF joint's origin, 1.5° of yaw off the published extrinsic, is
// refined back to it and called "refined", never "miscalibrated"; the published extrinsic read
// from a URDF export is the result file's; bad usage exits 1 naming the problem.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(CheckGuess, ATypedGuessIsRefinedOnRealRoadFramesNeverJudged) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto rig = shared / "datasets/opencalib-pandar64-scenes/rig-b";
  const auto dir = test::TempDir("check_guess");
  const std::string exe = test::CalibenchExe();
  const std::string dataset = " --dataset " + rig.string();
  std::string out;
  // The published extrinsic as the URDF joint `calibench export` writes (camera link frame).
  ASSERT_EQ(test::RunCommand(exe + " export -r " + (rig / "reference.result.json").string() +
                                 " -f urdf --camera-frame link -o " + (dir / "b.urdf").string(),
                             &out),
            0)
      << out;
  // Its origin, rounded as a person types it (metres, degrees): 0.546 -0.010 -0.387 and rpy
  // 0.04 0.76 0.22; yaw 1.5° off.
  const std::string typed = "0.546 -0.010 -0.387 0.04 0.76 1.72";
  ASSERT_EQ(test::RunCommand("(" + exe + " check" + dataset + " --guess '" + typed +
                                 "' --search-deg 3 --json > " + (dir / "guess.json").string() + ")",
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("refining: a guess: the link camera frame at x y z roll pitch yaw"),
            std::string::npos)
      << out;
  const nlohmann::json guess = nlohmann::json::parse(test::ReadFileBytes(dir / "guess.json"));
  EXPECT_EQ(guess.at("verdict"), "refined") << guess.at("why");
  EXPECT_EQ(guess.at("guess"), true);
  // The yaw comes back: about camera y, the change is the 1.5° typed in (within 0.3°).
  EXPECT_NEAR(guess.at("change_r_deg")[1].get<double>(), -1.5, 0.3) << guess.at("why");

  // The same pose as a calibration read from the URDF: the result file's change, to the digit.
  ASSERT_EQ(
      test::RunCommand("(" + exe + " check" + dataset + " -r " + (dir / "b.urdf").string() +
                           " --camera-frame link --json > " + (dir / "urdf.json").string() + ")",
                       &out),
      0)
      << out;
  ASSERT_EQ(test::RunCommand("(" + exe + " check" + dataset + " -r " +
                                 (rig / "reference.result.json").string() + " --json > " +
                                 (dir / "result.json").string() + ")",
                             &out),
            0)
      << out;
  const nlohmann::json urdf = nlohmann::json::parse(test::ReadFileBytes(dir / "urdf.json"));
  const nlohmann::json result = nlohmann::json::parse(test::ReadFileBytes(dir / "result.json"));
  EXPECT_EQ(urdf.at("guess"), false);
  EXPECT_NE(urdf.at("verdict"), "miscalibrated");
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(urdf.at("change_t_mm")[i].get<double>(), result.at("change_t_mm")[i].get<double>(),
                0.05);

  // Neither or both of --result and --guess, a guess that is not six numbers: exit 1 (bad usage),
  // said.
  EXPECT_EQ(test::RunCommand(exe + " check" + dataset, &out), 1);
  EXPECT_NE(out.find("one of them"), std::string::npos) << out;
  EXPECT_EQ(test::RunCommand(exe + " check" + dataset + " --guess '1 2 3'", &out), 1);
  EXPECT_NE(out.find("is not six numbers"), std::string::npos) << out;
  EXPECT_EQ(
      test::RunCommand(exe + " check" + dataset + " --guess '0 0 0 0 0 0' --camera-frame up", &out),
      1);
  EXPECT_NE(out.find("--camera-frame must be link or optical"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
