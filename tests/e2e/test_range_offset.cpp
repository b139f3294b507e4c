// Issue "Accuracy at the Cramér–Rao bound", item 7: the optional LiDAR range-offset parameter.
// A constant range error moves every board plane along its rays; without the parameter it lands
// in the translation, with it the offset is recovered with an honest standard deviation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/estimation/uncertainty.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

struct Solved {
  PoseError error;
  std::optional<RangeOffsetEstimate> offset;
  std::optional<RangeOffsetEstimate> unmodelled_offset;  // the score test's, when left out
  Vec3 translation_std = Vec3::Zero();
};

// A3 / HDL-64 at 1.5–6 m, 30 pairs, 8 mm range noise, the given range offset; features once,
// then the weighted solver without and with the offset parameter.
std::pair<Solved, Solved> SolveBoth(double offset_m, std::uint64_t seed) {
  SimOptions options = test::A3Hdl64Options(30, 0.008, seed);
  options.lidar_range_offset_m = offset_m;
  const Dataset dataset = SimulateDataset(
      options, test::TempDir("range_offset_" + std::to_string(static_cast<int>(offset_m * 1e3))));
  PipelineOptions pipeline;
  pipeline.threads = 2;
  std::vector<PairFeatures> features;
  for (const PairEntry& pair : dataset.pairs)
    features.push_back(ExtractPairFeatures(dataset, pair, pipeline));
  auto solve = [&](bool estimate) {
    PipelineOptions o = pipeline;
    o.solver.estimate_range_offset = estimate;
    const CalibrationOutcome outcome = SolveFromFeatures(features, o);
    EXPECT_TRUE(outcome.solution) << outcome.failure;
    Solved solved;
    if (!outcome.solution) return solved;
    solved.error =
        ComputePoseError(outcome.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
    solved.offset = outcome.solution->range_offset;
    solved.unmodelled_offset = outcome.solution->unmodelled_range_offset;
    solved.translation_std =
        TranslationStd(outcome.solution->covariance, outcome.solution->cam_from_lidar);
    return solved;
  };
  return {solve(false), solve(true)};
}

TEST(RangeOffset, RecoveredWithItsUncertaintyAndRemovedFromTheTranslation) {
  const auto [plain, with_offset] = SolveBoth(0.030, 11);
  ASSERT_TRUE(with_offset.offset);
  ASSERT_FALSE(plain.offset);
  const RangeOffsetEstimate& b = *with_offset.offset;
  std::printf(
      "true offset +30.0 mm: without the parameter %.1f mm / %.3f deg; with it %.1f mm / %.3f "
      "deg, offset %+.1f ± %.1f mm, correlation with translation x/y/z %.2f %.2f %.2f, "
      "translation std %.1f %.1f %.1f mm\n",
      plain.error.translation_m * 1e3, plain.error.rotation_rad * 180 / M_PI,
      with_offset.error.translation_m * 1e3, with_offset.error.rotation_rad * 180 / M_PI,
      b.value_m * 1e3, b.sigma_m * 1e3, b.correlation_with_translation.x(),
      b.correlation_with_translation.y(), b.correlation_with_translation.z(),
      with_offset.translation_std.x() * 1e3, with_offset.translation_std.y() * 1e3,
      with_offset.translation_std.z() * 1e3);
  // The offset is found within 3σ, and σ is small enough to mean something.
  EXPECT_LT(std::abs(b.value_m - 0.030), 3 * b.sigma_m);
  EXPECT_LT(b.sigma_m, 0.008);
  // Left out, it biases the translation by about its own size; estimated, the bias is gone.
  EXPECT_GT(plain.error.translation_m, 0.010);
  EXPECT_LT(with_offset.error.translation_m, 0.4 * plain.error.translation_m);
  // Left out, the solve still says that the data shows it (score test), near the truth.
  ASSERT_TRUE(plain.unmodelled_offset);
  EXPECT_FALSE(with_offset.unmodelled_offset);
  const RangeOffsetEstimate& hint = *plain.unmodelled_offset;
  std::printf("left out: unmodelled offset %+.1f ± %.1f mm\n", hint.value_m * 1e3,
              hint.sigma_m * 1e3);
  EXPECT_LT(std::abs(hint.value_m - 0.030), 3 * hint.sigma_m);
}

TEST(RangeOffset, ZeroOffsetIsFoundZeroAndCostsLittle) {
  const auto [plain, with_offset] = SolveBoth(0.0, 12);
  ASSERT_TRUE(with_offset.offset);
  const RangeOffsetEstimate& b = *with_offset.offset;
  std::printf(
      "true offset 0: without the parameter %.1f mm, with it %.1f mm, offset %+.1f ± %.1f mm\n",
      plain.error.translation_m * 1e3, with_offset.error.translation_m * 1e3, b.value_m * 1e3,
      b.sigma_m * 1e3);
  EXPECT_LT(std::abs(b.value_m), 3 * b.sigma_m);
  EXPECT_LT(with_offset.error.translation_m, 0.010);
  // Nothing to report when the sensor has no offset.
  EXPECT_FALSE(plain.unmodelled_offset);
}

TEST(RangeOffset, OnlyTheWeightedSolverEstimatesIt) {
  SolverOptions options;
  options.estimate_range_offset = true;
  options.method = SolverMethod::kCa2libGn;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("weighted-ml"), std::string::npos) << why;
}

}  // namespace
}  // namespace calibench
