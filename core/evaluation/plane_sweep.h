// The paper's Table 1 protocol (Ca²Lib Section 4.1) on simulated data: for each noise level,
// simulate a pool of pairs once, extract features once, then solve many random subsets of N pairs
// with every method, and compare the errors with the Cramér–Rao bound of each subset.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"

namespace calibench {

struct PlaneSweepOptions {
  SimOptions sim;  // the pool; its noise is set per level from the two lists below
  std::vector<int> sizes{3, 4, 5, 10, 20, 30, 39};     // numbers of pairs N
  std::vector<double> range_noise_m{0, 0.008, 0.016};  // LiDAR range noise per level (metres)
  std::vector<double> image_noise{0, 0.007, 0.014};    // image noise per level ([0,1] units)
  int subsets = 40;                                    // random subsets per N
  std::vector<SolverMethod> methods{SolverMethod::kWeightedMl, SolverMethod::kCa2libGn,
                                    SolverMethod::kKim};
  PipelineOptions pipeline;                      // extraction and solver options
  std::filesystem::path work_dir = "out/sweep";  // where each level's pool is written
  bool Check(std::string* why) const;
};

struct PlaneSweepCell {
  double mean_mm = 0, std_mm = 0, mean_deg = 0;  // translation and rotation error
  double ratio_t = 0, ratio_r = 0;               // RMS error / RMS bound over the subsets
  int weak = 0;                                  // subsets reported not well constrained
  int failures = 0;                              // subsets without a result
};

struct PlaneSweepResult {
  PlaneSweepOptions options;
  std::vector<std::vector<std::vector<PlaneSweepCell>>> cells;  // [method][size][noise level]
};

// log(line) reports simulation and extraction progress (failed pairs named).
PlaneSweepResult RunPlaneSweep(const PlaneSweepOptions& options,
                               const std::function<void(const std::string&)>& log = {});

// Markdown: per method, one row per N and one column per noise level.
std::string FormatPlaneSweepTable(const PlaneSweepResult& result);

}  // namespace calibench
