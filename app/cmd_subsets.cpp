// `calibench evaluate --subsets`: is the reported σ honest on this dataset?
// (core/evaluation/subset_coverage.h)
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/evaluation/subset_coverage.h"
#include "core/io/dataset.h"

namespace calibench::app {

int RunEvaluateSubsets(int argc, char** argv) {
  CLI::App app{
      "Calibrate the dataset's first k pairs and random subsets of k pairs, and count how "
      "often each result lies within its own 3σ (every axis) of the all-pairs result and, on a "
      "simulated set, of its ground truth: whether the reported σ can be trusted on these "
      "sensors.",
      "calibench evaluate --subsets"};
  std::string dataset_path, table_path;
  SubsetCoverageOptions coverage;
  bool subsets = false;
  app.add_flag("--subsets", subsets, "this mode");
  AddDatasetOption(app, &dataset_path, "a LiDAR-camera dataset")->required();
  app.add_option("--first-k", coverage.first_k, "prefix sizes (comma-separated)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--random-sizes", coverage.random_sizes, "random subset sizes (comma-separated)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--random-subsets", coverage.random_subsets, "random subsets per size")
      ->capture_default_str();
  app.add_option("--sigmas", coverage.coverage_sigmas, "coverage threshold in σ")
      ->capture_default_str();
  app.add_option("--seed", coverage.seed, "random subsets' seed")->capture_default_str();
  app.add_option("--table", table_path, "also write the table (Markdown) to this file");
  PipelineFlags flags;
  AddPipelineFlags(app, flags, /*with_selection=*/false);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  std::string why;
  if (!FinalizePipelineFlags(flags, &why) || !coverage.Check(&why)) {
    std::fprintf(stderr, "calibench evaluate --subsets: %s\n", why.c_str());
    return kUsage;
  }
  const Dataset dataset = LoadDataset(dataset_path);
  const CalibrationOutcome all =
      CalibrateDataset(dataset, flags.options, StderrProgress("extracted"));
  if (!all.solution) {
    std::fprintf(stderr, "calibench evaluate --subsets: no calibration for %s: %s\n",
                 dataset.manifest.string().c_str(), all.failure.c_str());
    return kNoCalibration;
  }
  const SubsetCoverage result = RunSubsetCoverage(
      all.pairs, flags.options, coverage,
      // A simulated set's ground truth is the truth; a real set's is someone's estimate.
      dataset.simulation ? dataset.cam_from_lidar_ground_truth : std::nullopt);
  const std::string table = FormatSubsetCoverage(result, coverage.coverage_sigmas);
  return PrintAndWriteTable(table, table_path, "calibench evaluate --subsets");
}

}  // namespace calibench::app
