// A pair the solve weights as if left out (the outlier gate's weight 0) is said to be so: in the
// summary, in the result file and (tests/ui) in the workbench's pair list.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace calibench
