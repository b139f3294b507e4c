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

TEST(DownWeighted, AGatedPairIsNamedInTheSummaryAndTheResult) {
  const fs::path dir = test::TempDir("down_weighted");
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 10;
  sim.seed = 4;
  const Dataset dataset = SimulateDataset(sim, dir / "sim");
  std::vector<PairFeatures> pairs;
  for (const PairEntry& entry : dataset.pairs)
    pairs.push_back(ExtractPairFeatures(dataset, entry, PipelineOptions{}));
  // Pair 3's camera plane 30 cm off: far beyond the others' agreement.
  ASSERT_TRUE(pairs[3].camera);
  pairs[3].camera->plane.distance += 0.3;
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

}  // namespace
}  // namespace calibench
