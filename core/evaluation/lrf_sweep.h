// The paper's evaluation protocol (Section 4.3, Fig. 8–9) on simulated data: errors against the
// number of observations, for each LRF method, averaged over seeds. Each seed simulates its own
// target poses and noise in memory; features are extracted once per observation and the first N
// observations are solved for every N.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/lrf/pipeline.h"
#include "core/sim/lrf_sim.h"

namespace calibench {

struct LrfSweepOptions {
  LrfSimOptions sim;  // observations is ignored: max(sizes) are simulated per seed
  std::vector<int> sizes{2, 3, 4, 6, 8, 10, 15, 20};
  int seeds = 20;
  std::uint64_t first_seed = 1;
  std::vector<LrfMethod> methods{LrfMethod::kPaperLinear, LrfMethod::kRefined};
  LrfPipelineOptions pipeline;
};

struct LrfSweepCell {
  double mean_rotation_deg = 0, std_rotation_deg = 0;
  double mean_translation_mm = 0, std_translation_mm = 0;
  int runs = 0;
  int failures = 0;  // seeds whose solve failed (or had fewer usable observations than N)
};

struct LrfSweepResult {
  std::vector<int> sizes;
  std::vector<LrfMethod> methods;
  std::vector<std::vector<LrfSweepCell>> cells;  // [method][size]
  int observations_failed = 0;  // feature extraction failures over all seeds (then replaced)
  int observations_total = 0;
};

// progress(seeds finished, seeds) after each seed (seeds run on options.pipeline.threads).
LrfSweepResult RunLrfSweep(const LrfSweepOptions& options,
                           const std::function<void(int, int)>& progress = {});

// Markdown: one row per N, one column pair (rotation, translation) per method.
std::string FormatLrfSweepTable(const LrfSweepResult& result);

}  // namespace calibench
