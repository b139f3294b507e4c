// A pair the solve weights as if left out (the outlier gate's weight 0) is said to be so: in the
// summary, in the result file and (tests/ui) in the workbench's pair list; a result too few pairs
// support is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// Ten simulated pairs, pair 3's camera plane 30 cm off: far beyond the others' agreement.
std::vector<PairFeatures> PairsWithOneFarOff(const fs::path& dir) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 10;
  sim.seed = 4;
  const Dataset dataset = SimulateDataset(sim, dir / "sim");
  std::vector<PairFeatures> pairs;
  for (const PairEntry& entry : dataset.pairs)
    pairs.push_back(ExtractPairFeatures(dataset, entry, PipelineOptions{}));
  EXPECT_TRUE(pairs[3].camera);
  if (pairs[3].camera) pairs[3].camera->plane.distance += 0.3;
  return pairs;
}

TEST(DownWeighted, AGatedPairIsNamedInTheSummaryAndTheResult) {
  const fs::path dir = test::TempDir("down_weighted");
  const std::vector<PairFeatures> pairs = PairsWithOneFarOff(dir);
  const PipelineOptions options;
  const CalibrationOutcome outcome = SolveFromFeatures(pairs, options);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  int down = 0;
  for (size_t i = 0; i < outcome.solution->robust_weights.size(); ++i)
    down += outcome.solution->DownWeighted(i);
  EXPECT_EQ(down, 1);
  EXPECT_TRUE(outcome.solution->DownWeighted(3));

  const std::string summary = FormatSummary(outcome);
  EXPECT_NE(
      summary.find("down-weighted to nothing (robust weight < 0.05): " + pairs[3].id + " (|e| "),
      std::string::npos)
      << summary;
  EXPECT_NE(summary.find("accepted, but in effect left out of the solve"), std::string::npos);

  WriteResult(dir / "result.json", outcome, options.solver);
  const nlohmann::json result = nlohmann::json::parse(std::ifstream(dir / "result.json"));
  for (size_t i = 0; i < result["pairs"].size(); ++i)
    EXPECT_EQ(result["pairs"][i]["down_weighted"].get<bool>(), i == 3) << i;
}

// The summary's numbers say what they compare: the cost from the last re-weighting on (the gated
// pair changes the weights mid-solve, so the first cost is not comparable with the last), and
// the covariance's widening by what widened it.
TEST(SummaryWords, TheCostAndTheWideningSayWhatTheirNumbersCompare) {
  CalibrationOutcome outcome =
      SolveFromFeatures(PairsWithOneFarOff(test::TempDir("summary_words")), PipelineOptions{});
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  SolverResult& s = *outcome.solution;
  ASSERT_GT(s.cost_comparable_from, 0) << "the gate re-weighted the pairs";
  char expected[160];
  std::snprintf(expected, sizeof(expected),
                "cost %.3e -> %.3e from iteration %d, when the pairs were last re-weighted",
                s.cost_history[s.cost_comparable_from], s.cost_history.back(),
                s.cost_comparable_from);
  std::string summary = FormatSummary(outcome);
  EXPECT_NE(summary.find(expected), std::string::npos) << summary;
  // Under one set of weights Gauss-Newton does not raise the cost.
  EXPECT_LE(s.cost_history.back(), s.cost_history[s.cost_comparable_from] * (1.0 + 1e-9));

  s.jackknife_widened = true;
  s.covariance_inflation = 1.0;
  summary = FormatSummary(outcome);
  EXPECT_NE(summary.find("covariance from the pairs' leave-one-out spread"), std::string::npos)
      << summary;
  EXPECT_EQ(summary.find("1.0x"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("x1.0"), std::string::npos) << summary;
  s.jackknife_widened = false;
  s.covariance_inflation = 2.5;
  summary = FormatSummary(outcome);
  EXPECT_NE(summary.find("covariance widened up to 2.50x (variance) by the spread"),
            std::string::npos)
      << summary;
}

// A result nothing supports is refused, never reported: when fewer than min_pairs accepted pairs
// keep a weight (the rest down-weighted to nothing). One whose σ exceeds what the boards can tell
// is never called well constrained.
TEST(Refusal, AResultTooFewPairsSupportIsRefusedATooUncertainOneNotWellConstrained) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 10;
  sim.seed = 4;
  const Dataset dataset = SimulateDataset(sim, test::TempDir("refusal") / "sim");
  std::vector<PairFeatures> pairs;
  for (const PairEntry& entry : dataset.pairs)
    pairs.push_back(ExtractPairFeatures(dataset, entry, PipelineOptions{}));
  const PipelineOptions options;
  const CalibrationOutcome solved = SolveFromFeatures(pairs, options);
  ASSERT_TRUE(solved.solution) << solved.failure;
  ASSERT_EQ(solved.solution->robust_weights.size(), 10u);

  CalibrationOutcome kept = solved;
  JudgeSolutionSupport(dataset.target, options, &kept);
  ASSERT_TRUE(kept.solution) << kept.failure;
  EXPECT_EQ(kept.failure, "");
  EXPECT_TRUE(kept.solution->observability.well_constrained);

  CalibrationOutcome two_left = solved;
  for (size_t i = 2; i < 10; ++i) two_left.solution->robust_weights[i] = 0.0;
  JudgeSolutionSupport(dataset.target, options, &two_left);
  EXPECT_FALSE(two_left.solution);
  EXPECT_NE(two_left.failure.find("8 of the 10 accepted pairs were down-weighted to nothing"),
            std::string::npos)
      << two_left.failure;
  EXPECT_NE(two_left.failure.find("only 2 support the result and at least 3 must"),
            std::string::npos)
      << two_left.failure;

  CalibrationOutcome three_left = solved;
  for (size_t i = 3; i < 10; ++i) three_left.solution->robust_weights[i] = 0.0;
  JudgeSolutionSupport(dataset.target, options, &three_left);
  EXPECT_TRUE(three_left.solution) << "three pairs fix all six degrees of freedom";

  // σ: the sheet's diagonal in translation; the angle it spans at the pairs' distance in rotation.
  const double diagonal_m = std::hypot(dataset.target.SheetWidth(), dataset.target.SheetHeight());
  CalibrationOutcome wide = solved;
  wide.solution->covariance.setZero();
  wide.solution->covariance.diagonal().head<3>().setConstant(std::pow(0.9 * diagonal_m, 2));
  JudgeSolutionSupport(dataset.target, options, &wide);
  ASSERT_TRUE(wide.solution);
  EXPECT_TRUE(wide.solution->observability.well_constrained)
      << "0.9 of the diagonal is still less than it";
  auto said = [](const CalibrationOutcome& outcome, const std::string& words) {
    for (const std::string& weak : outcome.solution->observability.weak_directions)
      if (weak.find(words) != std::string::npos) return true;
    return false;
  };
  wide = solved;
  wide.solution->covariance(1, 1) = std::pow(1.1 * diagonal_m, 2);
  JudgeSolutionSupport(dataset.target, options, &wide);
  ASSERT_TRUE(wide.solution) << "kept, with what it cannot tell";
  EXPECT_FALSE(wide.solution->observability.well_constrained);
  EXPECT_TRUE(said(wide, "exceeds what the boards can tell")) << FormatSummary(wide);
  EXPECT_NE(FormatSummary(wide).find("NOT well constrained"), std::string::npos);
  wide = solved;
  wide.solution->covariance(5, 5) = std::pow(0.5, 2);  // 29°: beyond any A3 sheet's span at 2 m+
  JudgeSolutionSupport(dataset.target, options, &wide);
  ASSERT_TRUE(wide.solution);
  EXPECT_FALSE(wide.solution->observability.well_constrained);
  EXPECT_TRUE(said(wide, "28.65 deg")) << FormatSummary(wide);
}

}  // namespace
}  // namespace calibench
