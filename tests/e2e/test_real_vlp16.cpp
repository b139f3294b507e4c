// Real data: ../shared/datasets/acfr-vlp16-chessboard (Velodyne VLP-16 + fisheye camera, 40
// chessboard pairs, the authors' reference extrinsic with a spread of about 4/18/30 mm).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "core/estimation/uncertainty.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
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
  std::printf("%d pairs accepted\n", accepted);
  test::ExpectNearAcfrReference(all.solution->cam_from_lidar, "all pairs");
  EXPECT_TRUE(all.solution->observability.well_constrained);
  ASSERT_TRUE(all.solution->edge_dilation);
  std::printf("board edges: %d crossings, sheet seen %.1f ± %.1f mm larger per side\n",
              all.solution->num_edge_residuals, all.solution->edge_dilation->value_m * 1e3,
              all.solution->edge_dilation->sigma_m * 1e3);
  // Half the VLP-16's beam footprint at 2–3 m is a few millimetres to a centimetre.
  EXPECT_GT(all.solution->edge_dilation->value_m, 0.002);
  EXPECT_LT(all.solution->edge_dilation->value_m, 0.015);

  // Spread over 10 random subsets of 20 pairs (features extracted once), for the default
  // weighted estimator, the same with the LiDAR range offset estimated, and the paper's, with the
  // reported σ beside it.
  std::vector<PairFeatures> pool;
  for (const PairFeatures& p : all.pairs)
    if (p.status == PairStatus::kAccepted) pool.push_back(p);
  struct Spread {
    Vec3 translation_std = Vec3::Zero();
    double max_angle = 0;
    Vec3 mean_reported_std = Vec3::Zero();
  };
  // CALIBENCH_REAL_SUBSETS widens the protocol's 10 subsets for steadier figures (not asserted).
  const char* subsets_env = std::getenv("CALIBENCH_REAL_SUBSETS");
  const int kSubsets = subsets_env ? std::max(10, std::atoi(subsets_env)) : 10;
  auto subsets = [&](const PipelineOptions& o) {
    std::mt19937_64 rng(2024);
    std::vector<Pose> estimates;
    Spread spread;
    for (int s = 0; s < kSubsets; ++s) {
      std::vector<PairFeatures> subset = pool;
      std::shuffle(subset.begin(), subset.end(), rng);
      subset.resize(20);
      const CalibrationOutcome outcome = SolveFromFeatures(subset, o);
      EXPECT_TRUE(outcome.solution);
      if (!outcome.solution) continue;
      estimates.push_back(outcome.solution->cam_from_lidar);
      spread.mean_reported_std +=
          TranslationStd(outcome.solution->covariance, outcome.solution->cam_from_lidar) / kSubsets;
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
  PipelineOptions paper_options = options;
  paper_options.solver.method = SolverMethod::kCa2libGn;
  PipelineOptions offset_options = options;
  offset_options.solver.estimate_range_offset = true;
  const Spread weighted = subsets(options);
  const Spread weighted_offset = subsets(offset_options);
  const Spread paper = subsets(paper_options);
  for (const auto& [name, sp] :
       {std::pair<const char*, Spread>{"weighted-ml", weighted},
        std::pair<const char*, Spread>{"weighted-ml + range offset", weighted_offset},
        std::pair<const char*, Spread>{"ca2lib-gn", paper}}) {
    std::printf(
        "%s, %d subsets of 20: translation std x/y/z = %.2f / %.2f / %.2f mm (RMS %.2f mm), max "
        "rotation from the all-pairs estimate %.3f deg; mean reported std %.1f / %.1f / %.1f mm\n",
        name, kSubsets, sp.translation_std.x() * 1e3, sp.translation_std.y() * 1e3,
        sp.translation_std.z() * 1e3, sp.translation_std.norm() * 1e3, sp.max_angle * 180 / M_PI,
        sp.mean_reported_std.x() * 1e3, sp.mean_reported_std.y() * 1e3,
        sp.mean_reported_std.z() * 1e3);
  }
  // Item 7 of issue 5: the optional range offset (the authors' README says their VLP-16 needed
  // a 30 mm correction). Reported with its σ and its correlation with the translation.
  PipelineOptions with_offset = options;
  with_offset.solver.estimate_range_offset = true;
  const CalibrationOutcome offset_outcome = SolveFromFeatures(pool, with_offset);
  ASSERT_TRUE(offset_outcome.solution) << offset_outcome.failure;
  ASSERT_TRUE(offset_outcome.solution->range_offset);
  const RangeOffsetEstimate& offset = *offset_outcome.solution->range_offset;
  const PoseError offset_error =
      ComputePoseError(offset_outcome.solution->cam_from_lidar, reference);
  std::printf(
      "with the range offset: %+.1f ± %.1f mm (correlation with translation x/y/z %.2f %.2f "
      "%.2f), %.1f mm, %.3f deg from the authors' reference\n",
      offset.value_m * 1e3, offset.sigma_m * 1e3, offset.correlation_with_translation.x(),
      offset.correlation_with_translation.y(), offset.correlation_with_translation.z(),
      offset_error.translation_m * 1e3, offset_error.rotation_rad * 180 / M_PI);
  // What the data says: −23 ± 1.3 mm, near the −30 mm the authors' README names for their
  // sensor, and well determined with the board edges (without them ± 5 mm, correlated 0.99 with
  // the camera-z translation). It moves the estimate further from the authors' mean (their tool
  // ran without the correction), so it stays off by default.
  EXPECT_TRUE(offset.well_determined);
  EXPECT_FALSE(offset_outcome.solution->unmodelled_range_offset);
  // The default solve, which leaves the offset out, says that the data shows one, near where
  // estimating it lands.
  ASSERT_TRUE(all.solution->unmodelled_range_offset);
  const RangeOffsetEstimate& unmodelled = *all.solution->unmodelled_range_offset;
  std::printf("default solve: unmodelled range offset %+.1f ± %.1f mm\n", unmodelled.value_m * 1e3,
              unmodelled.sigma_m * 1e3);
  EXPECT_NEAR(unmodelled.value_m, offset.value_m, 3 * unmodelled.sigma_m);
  EXPECT_LT(offset.value_m, -0.01);
  EXPECT_GT(offset.value_m, -0.05);
  EXPECT_GT(offset.correlation_with_translation.cwiseAbs().maxCoeff(), 0.5);
  const Vec3 std_plain = TranslationStd(all.solution->covariance, all.solution->cam_from_lidar);
  const Vec3 std_offset =
      TranslationStd(offset_outcome.solution->covariance, offset_outcome.solution->cam_from_lidar);
  std::printf("translation std without / with the offset: z %.1f / %.1f mm\n", std_plain.z() * 1e3,
              std_offset.z() * 1e3);
  EXPECT_GE(std_offset.z(), 0.9 * std_plain.z());

  // Spread against the paper's estimator. Subsets must agree with each other well inside the
  // authors' own spread (4/18/30 mm). The default's rotation and camera-y translation (the boards'
  // vertical in-plane direction, which the edges fix) are much steadier than the paper's, and so is
  // its translation as a whole; camera x and z alone are no steadier. What moves x is the VLP-16's
  // uncorrected range offset (the dataset's README: the sensor needs about −30 mm): a range error
  // moves each board along its rays, sideways for the boards off to one side, and which boards a
  // subset holds decides how much of that shows. Estimated, the offset halves the x spread;
  // per-ring angle offsets of the LiDAR, which we suspected first, explain almost nothing of the
  // edge residuals (docs/results.md, "Real data"). z pays for the offset it shares its information
  // with.
  const double kDegree = M_PI / 180;
  for (const Spread* sp : {&weighted, &weighted_offset}) {
    EXPECT_LT(sp->translation_std.maxCoeff(), 0.02);
    EXPECT_LT(sp->max_angle, 1.0 * kDegree);
    EXPECT_LT(sp->max_angle, 0.5 * paper.max_angle);
    EXPECT_LT(sp->translation_std.norm(), 0.95 * paper.translation_std.norm());
    EXPECT_LT(sp->translation_std.y(), 0.8 * paper.translation_std.y());
    EXPECT_LT(sp->translation_std.z(), 1.3 * paper.translation_std.z());
  }
  EXPECT_LT(weighted.translation_std.x(), 1.3 * paper.translation_std.x());
  EXPECT_LT(weighted_offset.translation_std.x(), 0.7 * paper.translation_std.x());
  EXPECT_LT(weighted_offset.translation_std.norm(), 0.75 * paper.translation_std.norm());
  // Calibrated uncertainty: subsets of 20 drawn from the same 40 pairs share half their pairs on
  // average, so their spread is √((40 − 20) / (40 − 1)) = 0.72 times that of independent sets of
  // 20 pairs (the finite-population correction), which is what the reported σ describes.
  const double shared_pairs_factor = std::sqrt((pool.size() - 20.0) / (pool.size() - 1.0));
  for (const auto& [name, sp] :
       {std::pair<const char*, Spread>{"weighted-ml", weighted},
        std::pair<const char*, Spread>{"weighted-ml + range offset", weighted_offset}}) {
    const Vec3 independent_spread = sp.translation_std / shared_pairs_factor;
    std::printf(
        "%s: reported σ / spread of independent sets x/y/z = %.2f / %.2f / %.2f (raw subset "
        "spread: %.2f / %.2f / %.2f)\n",
        name, sp.mean_reported_std.x() / independent_spread.x(),
        sp.mean_reported_std.y() / independent_spread.y(),
        sp.mean_reported_std.z() / independent_spread.z(),
        sp.mean_reported_std.x() / sp.translation_std.x(),
        sp.mean_reported_std.y() / sp.translation_std.y(),
        sp.mean_reported_std.z() / sp.translation_std.z());
    for (int k = 0; k < 3; ++k) {
      const double ratio = sp.mean_reported_std[k] / independent_spread[k];
      EXPECT_GT(ratio, 0.5) << name << ", axis " << k;
      EXPECT_LT(ratio, 2.0) << name << ", axis " << k;
    }
  }
}

TEST(RealVlp16, NoSeedsNoBrushingTheBoardIsDetectedInEveryCloud) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const auto acfr = shared / "datasets/acfr-vlp16-chessboard";
  const Dataset folder =
      LoadDataset(test::WriteAcfrFolder(acfr, test::TempDir("real_vlp16_folder")));
  const Dataset seeded =
      LoadDataset(test::WriteAcfrManifest(acfr, test::TempDir("real_vlp16_seeded")));
  ASSERT_EQ(folder.pairs.size(), 40u);
  for (const PairEntry& pair : folder.pairs) ASSERT_FALSE(pair.lidar_seed);

  PipelineOptions options;
  options.threads = 2;
  const CalibrationOutcome detected = CalibrateDataset(folder, options);
  const CalibrationOutcome reference = CalibrateDataset(seeded, options);
  ASSERT_TRUE(detected.solution) << detected.failure;
  ASSERT_TRUE(reference.solution) << reference.failure;
  EXPECT_TRUE(detected.background_note.empty()) << detected.background_note;

  std::map<std::string, const PairFeatures*> seeded_pairs;
  for (const PairFeatures& p : reference.pairs) seeded_pairs[p.id] = &p;
  int found = 0, wrong = 0;
  std::printf("pair     source         conf  angle to seeded  offset\n");
  for (const PairFeatures& p : detected.pairs) {
    if (!p.lidar) {
      std::printf("%-8s %s\n", p.id.c_str(), p.reason.c_str());
      continue;
    }
    ++found;
    const PairFeatures& s = *seeded_pairs.at(p.id);
    ASSERT_TRUE(s.lidar) << p.id;
    const double angle =
        std::acos(std::min(1.0, std::abs(p.lidar->plane.normal.dot(s.lidar->plane.normal))));
    const double offset = std::abs(p.lidar->plane.distance - s.lidar->plane.distance);
    const bool false_detection = angle > 2.0 * kDegToRad || offset > 0.03;
    wrong += false_detection;
    std::printf("%-8s %-13s  %.2f  %6.3f deg       %5.1f mm%s\n", p.id.c_str(),
                BoardSourceName(p.board_origin.source).c_str(), p.board_origin.confidence,
                angle * kRadToDeg, offset * 1e3, false_detection ? "  FALSE" : "");
    EXPECT_NE(p.board_origin.source, BoardSource::kSeed);
  }
  const PoseError apart =
      ComputePoseError(detected.solution->cam_from_lidar, reference.solution->cam_from_lidar);
  std::printf("%d of 40 detected, %d false; calibration %.2f mm / %.4f deg from the seeded one\n",
              found, wrong, apart.translation_m * 1e3, apart.rotation_rad * kRadToDeg);
  EXPECT_GE(found, 38);
  EXPECT_EQ(wrong, 0);
  EXPECT_LT(apart.translation_m, 0.002);
  EXPECT_LT(apart.rotation_rad, 0.05 * kDegToRad);
}

}  // namespace
}  // namespace calibench
