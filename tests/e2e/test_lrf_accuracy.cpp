// Issue "2D LRF ↔ depth camera", Show: on simulated data with the paper's noise (R2000 ±25 mm,
// ZED-like depth), at 2 and at 10 observations over 20 seeds, the refined SE(3) estimator beats
// the paper's linear least squares on mean rotation and translation error, and both stay within
// stated bounds.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/evaluation/lrf_sweep.h"

namespace calibench {
namespace {

TEST(LrfAccuracy, RefinedBeatsPaperLinearAtTwoAndTenObservations) {
  LrfSweepOptions options;
  options.sim = *LrfSimPreset("paper");
  options.sizes = {2, 10};
  options.seeds = 20;
  const LrfSweepResult result = RunLrfSweep(options);
  std::printf("%s", FormatLrfSweepTable(result).c_str());
  ASSERT_EQ(result.methods[0], LrfMethod::kPaperLinear);
  ASSERT_EQ(result.methods[1], LrfMethod::kRefined);
  // Feature extraction works on the simulated observations.
  EXPECT_LE(result.observations_failed, result.observations_total / 10);
  for (size_t i = 0; i < result.sizes.size(); ++i) {
    const LrfSweepCell& paper = result.cells[0][i];
    const LrfSweepCell& refined = result.cells[1][i];
    SCOPED_TRACE("N = " + std::to_string(result.sizes[i]));
    EXPECT_EQ(paper.failures, 0);
    EXPECT_EQ(refined.failures, 0);
    EXPECT_LT(refined.mean_rotation_deg, paper.mean_rotation_deg);
    EXPECT_LT(refined.mean_translation_mm, paper.mean_translation_mm);
  }
  // Stated bounds (the paper: 3.74 deg / 28.31 mm at 2 observations, 0.68 deg / 6.67 mm with
  // many, on its stereo-baseline check).
  // Errors here are against the ground-truth extrinsic; the paper's are on the stereo baseline,
  // where any error common to the left and right calibrations cancels. Two upright poses leave
  // the scan plane's tilt weakly constrained, hence the wide bounds at N = 2.
  EXPECT_LT(result.cells[0][0].mean_rotation_deg, 15.0);
  EXPECT_LT(result.cells[0][0].mean_translation_mm, 500.0);
  EXPECT_LT(result.cells[1][0].mean_rotation_deg, 10.0);
  EXPECT_LT(result.cells[1][0].mean_translation_mm, 300.0);
  EXPECT_LT(result.cells[0][1].mean_rotation_deg, 0.8);
  EXPECT_LT(result.cells[0][1].mean_translation_mm, 20.0);
  EXPECT_LT(result.cells[1][1].mean_rotation_deg, 0.6);
  EXPECT_LT(result.cells[1][1].mean_translation_mm, 15.0);
}

}  // namespace
}  // namespace calibench
