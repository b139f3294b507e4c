// The worker count is a speed setting only: the same input gives byte-identical output on one
// thread and on several (every parallel loop writes per-index slots, reduced in index order).
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/evaluation/lrf_sweep.h"
#include "core/evaluation/plane_sweep.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

TEST(Threads, CalibrateWritesTheSameBytesOnOneThreadAndOnSeveral) {
  const fs::path dir = test::TempDir("threads_calibrate_" + std::to_string(getpid()));
  SimOptions sim = SimPreset("default");
  sim.num_pairs = 8;
  sim.seed = 11;
  sim.lidar_range_noise_m = 0.01;
  sim.image_noise = 0.01;
  SimulateDataset(sim, dir / "data");
  // Without seeds: the parallel background model, detection and camera-guided completion run too.
  nlohmann::json manifest = nlohmann::json::parse(std::ifstream(dir / "data/dataset.json"));
  for (auto& pair : manifest["pairs"]) pair.erase("lidar_seed");
  std::ofstream(dir / "data/dataset.json") << manifest.dump(2);
  std::string results[3];
  const int threads[3] = {1, 3, 0};  // 0: the default (the machine's hardware threads)
  for (int k = 0; k < 3; ++k) {
    const fs::path out = dir / ("result_" + std::to_string(k) + ".json");
    std::string log;
    const std::string flag = threads[k] > 0 ? " --threads " + std::to_string(threads[k]) : "";
    ASSERT_EQ(
        test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                             (dir / "data/dataset.json").string() + " --out " + out.string() + flag,
                         &log),
        0)
        << log;
    results[k] = test::ReadFileBytes(out);
    ASSERT_FALSE(results[k].empty());
  }
  EXPECT_EQ(results[0], results[1]) << "--threads 1 and --threads 3 differ";
  EXPECT_EQ(results[0], results[2]) << "--threads 1 and the default differ";
}

TEST(Threads, PlaneSweepTableDoesNotDependOnTheThreadCount) {
  const fs::path dir = test::TempDir("threads_sweep_" + std::to_string(getpid()));
  PlaneSweepOptions options;
  options.sim = SimPreset("default");
  options.sim.num_pairs = 8;
  options.sizes = {3, 6};
  options.range_noise_m = {0.008};
  options.image_noise = {0.007};
  options.subsets = 6;
  std::string tables[2];
  for (int k = 0; k < 2; ++k) {
    options.pipeline.threads = k == 0 ? 1 : 3;
    options.work_dir = dir / std::to_string(k);
    const PlaneSweepResult result = RunPlaneSweep(options);
    tables[k] = FormatPlaneSweepTable(result);
    ASSERT_EQ(result.cells[0][0][0].failures, 0) << tables[k];
  }
  EXPECT_EQ(tables[0], tables[1]);
}

TEST(Threads, LrfSweepTableDoesNotDependOnTheThreadCount) {
  LrfSweepOptions options;
  options.sim = *LrfSimPreset("paper");
  options.sizes = {3, 5};
  options.seeds = 4;
  std::string tables[2];
  int runs[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    options.pipeline.threads = k == 0 ? 1 : 3;
    int last_progress = 0;
    const LrfSweepResult result = RunLrfSweep(options, [&](int done, int total) {
      EXPECT_EQ(total, options.seeds);
      EXPECT_EQ(done, last_progress + 1);
      last_progress = done;
    });
    EXPECT_EQ(last_progress, options.seeds);
    tables[k] = FormatLrfSweepTable(result);
    runs[k] = result.cells[1][1].runs;
  }
  EXPECT_EQ(runs[0], options.seeds);
  EXPECT_EQ(tables[0], tables[1]);
}

}  // namespace
}  // namespace calibench
