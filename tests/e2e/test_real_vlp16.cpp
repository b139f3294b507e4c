// Real data: ../shared/datasets/acfr-vlp16-chessboard (Velodyne VLP-16 + fisheye camera, 40
// chessboard pairs, the authors' reference extrinsic with a spread of about 4/18/30 mm).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "core/pipeline.h"
#include "core/result_io.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(RealVlp16, AllPairsLandNearTheAuthorsReference) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto manifest = test::WriteAcfrManifest(shared / "datasets/acfr-vlp16-chessboard",
                                                test::TempDir("real_vlp16"));
  const Dataset dataset = LoadDataset(manifest);
  ASSERT_EQ(dataset.pairs.size(), 40u);
  EXPECT_EQ(dataset.camera.type, CameraModelType::kKannalaBrandt);

  PipelineOptions options;
  options.threads = 2;
  const CalibrationOutcome all = CalibrateDataset(dataset, options);
  int accepted = 0;
  for (const PairFeatures& p : all.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    if (p.status != PairStatus::kAccepted)
      std::printf("pair %s: %s\n", p.id.c_str(), p.reason.c_str());
  }
  ASSERT_TRUE(all.solution) << all.failure;
  EXPECT_GE(accepted, 36);
  const Pose reference = test::AcfrReferenceCamFromLidar();
  const PoseError error = ComputePoseError(all.solution->cam_from_lidar, reference);
  std::printf("all %d pairs: %.1f mm, %.3f deg from the authors' reference\n", accepted,
              error.translation_m * 1e3, error.rotation_rad * 180 / M_PI);
  EXPECT_LT(error.translation_m, 0.04);
  EXPECT_LT(error.rotation_rad, 1.0 * M_PI / 180);
  EXPECT_TRUE(all.solution->observability.well_constrained);

  // Spread over 10 random subsets of 20 pairs (features extracted once), for the default
  // weighted estimator and the paper's, with the weighted solver's reported σ beside it.
  std::vector<PairFeatures> pool;
  for (const PairFeatures& p : all.pairs)
    if (p.status == PairStatus::kAccepted) pool.push_back(p);
  struct Spread {
    Vec3 translation_std = Vec3::Zero();
    double max_angle = 0;
    Vec3 mean_reported_std = Vec3::Zero();
  };
  auto subsets = [&](SolverMethod method) {
    std::mt19937_64 rng(2024);
    PipelineOptions o = options;
    o.solver.method = method;
    std::vector<Pose> estimates;
    Spread spread;
    for (int s = 0; s < 10; ++s) {
      std::vector<PairFeatures> subset = pool;
      std::shuffle(subset.begin(), subset.end(), rng);
      subset.resize(20);
      const CalibrationOutcome outcome = SolveFromFeatures(subset, o);
      EXPECT_TRUE(outcome.solution);
      if (!outcome.solution) continue;
      estimates.push_back(outcome.solution->cam_from_lidar);
      spread.mean_reported_std +=
          TranslationStd(outcome.solution->covariance, outcome.solution->cam_from_lidar) / 10.0;
    }
    Vec3 mean = Vec3::Zero();
    for (const Pose& p : estimates) mean += p.translation() / estimates.size();
    for (const Pose& p : estimates) {
      spread.translation_std += (p.translation() - mean).cwiseAbs2() / (estimates.size() - 1);
      spread.max_angle = std::max(spread.max_angle,
                                  RotationAngle(p.linear(), all.solution->cam_from_lidar.linear()));
    }
    spread.translation_std = spread.translation_std.cwiseSqrt();
    return spread;
  };
  const Spread weighted = subsets(SolverMethod::kWeightedMl);
  const Spread paper = subsets(SolverMethod::kCa2libGn);
  for (const auto& [name, sp] : {std::pair<const char*, Spread>{"weighted-ml", weighted},
                                 std::pair<const char*, Spread>{"ca2lib-gn", paper}}) {
    std::printf(
        "%s, 10 subsets of 20: translation std x/y/z = %.1f / %.1f / %.1f mm, max rotation from "
        "the all-pairs estimate %.3f deg; mean reported std %.1f / %.1f / %.1f mm\n",
        name, sp.translation_std.x() * 1e3, sp.translation_std.y() * 1e3,
        sp.translation_std.z() * 1e3, sp.max_angle * 180 / M_PI, sp.mean_reported_std.x() * 1e3,
        sp.mean_reported_std.y() * 1e3, sp.mean_reported_std.z() * 1e3);
  }
  const Vec3 spread = weighted.translation_std;
  const double max_angle = weighted.max_angle;
  // Subsets must agree with each other well inside the authors' own spread (4/18/30 mm).
  EXPECT_LT(spread.maxCoeff(), 0.02);
  EXPECT_LT(max_angle, 1.0 * M_PI / 180);
}

}  // namespace
}  // namespace calibench
