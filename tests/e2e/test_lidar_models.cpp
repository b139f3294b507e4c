// Issue 32 item 6: the sensor's geometry decides the LiDAR noise model. A swept single-line laser
// (a 2D scanner on a rotary stage, its mirror off the axis) and board-only segments are told from
// a spinning LiDAR by their clouds, fitted with the isotropic model and said so; on the swept
// simulation the default solver is at least as accurate as the paper's, with σ that covers its
// error; without seeds the result is the seeded one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/evaluation/subset_coverage.h"
#include "core/io/cloud_io.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/sim/sim.h"
#include "tests/acfr_manifest.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

SimOptions Swept(std::uint64_t seed) {
  SimOptions sim = SimPreset("default");
  sim.lidar = LidarModel::kSwept2d;
  sim.num_pairs = 10;
  sim.lidar_range_noise_m = 0.005;
  sim.image_noise = 0.02;
  sim.seed = seed;
  return sim;
}

TEST(LidarModels, EachCloudKindIsToldFromItsCloud) {
  const fs::path dir = test::TempDir("lidar_models_kinds");
  SimOptions spinning = SimPreset("default");
  spinning.num_pairs = 1;
  const Dataset vlp16 = SimulateDataset(spinning, dir / "vlp16");
  LidarCloud cloud = LoadCloud(vlp16.pairs[0].cloud);
  EXPECT_EQ(ClassifyLidarGeometry(cloud).geometry, LidarGeometry::kSpinning);
  // Without its ring field a spinning scan is still one: its returns lie on cones.
  cloud.ring.clear();
  const LidarGeometryVerdict ringless = ClassifyLidarGeometry(cloud);
  EXPECT_EQ(ringless.geometry, LidarGeometry::kSpinning) << ringless.why;
  EXPECT_NE(ringless.why.find("lie on 16 cones of elevation"), std::string::npos) << ringless.why;

  SimOptions swept = Swept(1);
  swept.num_pairs = 1;
  const LidarGeometryVerdict verdict =
      ClassifyLidarGeometry(LoadCloud(SimulateDataset(swept, dir / "swept").pairs[0].cloud));
  EXPECT_EQ(verdict.geometry, LidarGeometry::kSwept) << verdict.why;
  EXPECT_NE(verdict.why.find("rays do not meet at the origin"), std::string::npos);

  spinning.board_only_clouds = true;
  const LidarGeometryVerdict segment =
      ClassifyLidarGeometry(LoadCloud(SimulateDataset(spinning, dir / "segment").pairs[0].cloud));
  EXPECT_EQ(segment.geometry, LidarGeometry::kSegment) << segment.why;
  EXPECT_NE(segment.why.find("a segment"), std::string::npos);
}

struct Errors {
  double translation_m = 0.0;
  double rotation_rad = 0.0;
  double nees = 0.0;  // (error)ᵀ Σ⁻¹ (error), 6 dof
};

Errors ErrorsOf(const SolverResult& solution, const Pose& truth) {
  const PoseError error = ComputePoseError(solution.cam_from_lidar, truth);
  // The error as the right perturbation of the estimate: truth = estimate · Exp(delta).
  const Vec6 delta = LogSE3(solution.cam_from_lidar.inverse() * truth);
  return {error.translation_m, error.rotation_rad,
          delta.dot(solution.covariance.ldlt().solve(delta))};
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The bar: on the swept simulation (10 seeds of 10 pairs), the default (weighted-ml with
// the model chosen from the clouds) is at least as accurate as ca2lib-gn, and as forcing the
// spinning model, by the median, and its σ covers its error (the mean NEES near 6, not several
// times it).
TEST(LidarModels, OnASweptLaserTheDefaultIsAtLeastAsAccurateAsThePapersSolver) {
  const fs::path dir = test::TempDir("lidar_models_swept");
  std::vector<double> weighted_t, paper_t, forced_t, weighted_r, paper_r, forced_r, nees;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Dataset dataset = SimulateDataset(Swept(seed), dir / std::to_string(seed));
    const Pose truth = *dataset.cam_from_lidar_ground_truth;
    const CalibrationOutcome weighted = CalibrateDataset(dataset, PipelineOptions{});
    PipelineOptions paper;
    paper.solver.method = SolverMethod::kCa2libGn;
    const CalibrationOutcome gn = CalibrateDataset(dataset, paper);
    PipelineOptions forced;
    forced.lidar_model = LidarGeometry::kSpinning;  // the ray model of a central spinning LiDAR
    const CalibrationOutcome central = CalibrateDataset(dataset, forced);
    ASSERT_TRUE(weighted.solution && gn.solution && central.solution);
    if (seed == 1) {
      const std::string model = DescribeLidarModel(weighted);
      EXPECT_EQ(model.rfind("LiDAR model: swept for all ", 0), 0u) << model;
      // The mirror is estimated from each scan (core/lidar/swept_origin.h) and the planes are
      // fitted along its rays: the noise along them is learned, the 5 mm the simulator drew.
      EXPECT_NE(model.find("(estimated: the beams' angles"), std::string::npos) << model;
      EXPECT_NE(model.find("along each return's own ray"), std::string::npos) << model;
      EXPECT_NE(FormatSummary(weighted).find(model), std::string::npos);
      const std::string noise = DescribeLearnedLidarNoise(weighted);
      EXPECT_NE(noise.find("range sigma 5.0 mm"), std::string::npos) << noise;
      EXPECT_NE(DescribeLearnedLidarNoise(central).find("angular"), std::string::npos);
      EXPECT_NE(DescribeLidarModel(central).find("chosen by the user (--lidar-model)"),
                std::string::npos);
    }
    const Errors w = ErrorsOf(*weighted.solution, truth);
    const Errors g = ErrorsOf(*gn.solution, truth);
    const Errors c = ErrorsOf(*central.solution, truth);
    std::printf(
        "seed %2d: weighted-ml %.2f mm %.3f deg (NEES %.1f) | ca2lib-gn %.2f mm %.3f deg | "
        "forced spinning %.2f mm %.3f deg\n",
        int(seed), w.translation_m * 1e3, w.rotation_rad * kRadToDeg, w.nees, g.translation_m * 1e3,
        g.rotation_rad * kRadToDeg, c.translation_m * 1e3, c.rotation_rad * kRadToDeg);
    weighted_t.push_back(w.translation_m);
    weighted_r.push_back(w.rotation_rad);
    paper_t.push_back(g.translation_m);
    paper_r.push_back(g.rotation_rad);
    forced_t.push_back(c.translation_m);
    forced_r.push_back(c.rotation_rad);
    nees.push_back(w.nees);
  }
  double mean_nees = 0;
  for (double v : nees) mean_nees += v / nees.size();
  std::printf(
      "median translation: weighted-ml %.2f mm, ca2lib-gn %.2f mm, forced spinning %.2f mm; "
      "median rotation %.3f vs %.3f vs %.3f deg; mean NEES %.1f (6 = σ exact)\n",
      Median(weighted_t) * 1e3, Median(paper_t) * 1e3, Median(forced_t) * 1e3,
      Median(weighted_r) * kRadToDeg, Median(paper_r) * kRadToDeg, Median(forced_r) * kRadToDeg,
      mean_nees);
  EXPECT_LE(Median(weighted_t), Median(paper_t));
  EXPECT_LE(Median(weighted_r), Median(paper_r));
  // Issue 46: the default at least as accurate as forcing the spinning model's rays from the
  // origin (measured: 1.24 mm / 0.060° against 1.70 mm / 0.071°; the paper 4.74 mm / 0.093°).
  EXPECT_LE(Median(weighted_t), Median(forced_t));
  EXPECT_LE(Median(weighted_r), Median(forced_r));
  EXPECT_LT(mean_nees, 12.0);
}

// Issue 46 item 2: a narrow field of view is not a segment. A line scanner nodded through ±20°
// (a 28° window on the room, its mirror a few cm off the tilt axis) and a Livox Mid-40's 38°
// circle are whole scans: judged so from the returns' extent, fitted along their rays, and the
// default at least as accurate as forcing the spinning model (within 10 % by the median of 4
// sets, the two differing only by the ring biases the forced model adds).
TEST(LidarModels, ANarrowScanIsAScanNotASegment) {
  const fs::path dir = test::TempDir("lidar_models_narrow");
  std::vector<double> default_t, forced_t, default_r, forced_r;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    SimOptions sim = SimPreset("default");
    sim.lidar = LidarModel::kNodding2d;
    sim.num_pairs = 12;
    sim.min_distance_m = 1.5;
    sim.max_distance_m = 4.0;
    sim.lidar_range_noise_m = 0.01;
    sim.image_noise = 0.02;
    sim.seed = seed;
    const Dataset dataset = SimulateDataset(sim, dir / std::to_string(seed));
    const LidarGeometryVerdict verdict = ClassifyLidarGeometry(LoadCloud(dataset.pairs[0].cloud));
    EXPECT_EQ(verdict.geometry, LidarGeometry::kNonRepetitive) << verdict.why;
    EXPECT_LT(AzimuthCoverageDeg(LoadCloud(dataset.pairs[0].cloud)), 40.0);
    const CalibrationOutcome judged = CalibrateDataset(dataset, PipelineOptions{});
    PipelineOptions forced;
    forced.lidar_model = LidarGeometry::kSpinning;
    const CalibrationOutcome spinning = CalibrateDataset(dataset, forced);
    ASSERT_TRUE(judged.solution && spinning.solution);
    // Judged a scan, and the held-out pairs (asked between its rays and point-to-plane) keep it.
    const std::string model = DescribeLidarModel(judged);
    EXPECT_EQ(model.rfind("LiDAR model: non-repetitive for all 12 pairs (no rings", 0), 0u)
        << model;
    if (seed == 1) std::printf("%s\n", model.c_str());
    const Pose truth = *dataset.cam_from_lidar_ground_truth;
    const Errors d = ErrorsOf(*judged.solution, truth);
    const Errors f = ErrorsOf(*spinning.solution, truth);
    std::printf(
        "nodding seed %d: default %.2f mm %.3f deg (NEES %.1f) | forced spinning %.2f mm "
        "%.3f deg\n",
        int(seed), d.translation_m * 1e3, d.rotation_rad * kRadToDeg, d.nees, f.translation_m * 1e3,
        f.rotation_rad * kRadToDeg);
    default_t.push_back(d.translation_m);
    forced_t.push_back(f.translation_m);
    default_r.push_back(d.rotation_rad);
    forced_r.push_back(f.rotation_rad);
  }
  EXPECT_LE(Median(default_t), 1.1 * Median(forced_t));
  EXPECT_LE(Median(default_r), 1.1 * Median(forced_r));
  // A Mid-40's cloud: 38° of azimuth, a scan.
  SimOptions livox = SimPreset("default");
  livox.lidar = LidarModel::kMid40;
  livox.num_pairs = 1;
  const LidarCloud rosette = LoadCloud(SimulateDataset(livox, dir / "mid40").pairs[0].cloud);
  EXPECT_LT(AzimuthCoverageDeg(rosette), 45.0);
  EXPECT_EQ(ClassifyLidarGeometry(rosette).geometry, LidarGeometry::kNonRepetitive);
}

// The noise model learned from the data (core/target/lidar_noise.h), from the command line: a
// VLP-16 set whose beams jitter 0.3° across their rays says so in the result and the summary, the
// same set without the jitter bounds the term instead. Range noise 1 cm in both.
TEST(LidarModels, TheAngularNoiseIsLearnedFromTheBoardsAndSaid) {
  const fs::path dir = test::TempDir("lidar_models_angular");
  for (const double jitter_deg : {0.3, 0.0}) {
    const fs::path set = dir / std::to_string(jitter_deg);
    char command[512];
    std::snprintf(command, sizeof(command),
                  " simulate --out %s --lidar vlp16 --pairs 12 --lidar-noise 0.01 "
                  "--lidar-angular-noise-deg %.2f --seed 3 > /dev/null",
                  set.string().c_str(), jitter_deg);
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + command), 0);
    std::string summary;
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + set.string() +
                                   " --out " + (set / "result.json").string() + " 2>&1",
                               &summary),
              0)
        << summary;
    const nlohmann::json noise =
        nlohmann::json::parse(test::ReadFileBytes(set / "result.json")).at("lidar_noise");
    std::printf("jitter %.1f deg: %s\n", jitter_deg, noise.dump().c_str());
    EXPECT_EQ(noise.at("boards").get<int>(), 12);
    EXPECT_NEAR(noise.at("range_sigma_m").at("median").get<double>(), 0.01, 0.0015);
    if (jitter_deg > 0) {
      EXPECT_TRUE(noise.at("angular_resolved").get<bool>());
      EXPECT_NEAR(noise.at("angular_sigma_deg").get<double>(), jitter_deg, 0.25 * jitter_deg);
      EXPECT_NE(summary.find("angular sigma 0."), std::string::npos) << summary;
    } else {
      EXPECT_FALSE(noise.at("angular_resolved").get<bool>());
      EXPECT_LT(noise.at("angular_sigma_upper_deg").get<double>(), 0.25);
      EXPECT_NE(summary.find("no angular term resolved"), std::string::npos) << summary;
    }
  }
}

// A swept scanner whose driver writes each return's ray origin (its mirror as the stage turned it:
// vp_x, vp_y, vp_z): its planes are fitted along those rays, the noise along them is learned, and
// the summary says so. 2 cm of range noise, seedless, the mirror 10 cm off the stage's axis. The
// same scans without viewpoints: the mirror estimated from each scan gives the same result.
TEST(LidarModels, ASweptScannersViewpointsAreItsRays) {
  const fs::path dir = test::TempDir("lidar_models_viewpoints");
  SimOptions sim = Swept(3);
  sim.num_pairs = 12;
  sim.lidar_range_noise_m = 0.02;
  sim.lidar_seeds = false;
  sim.lidar_viewpoints = true;
  const Dataset dataset = SimulateDataset(sim, dir / "set");
  ASSERT_TRUE(LoadCloud(dataset.pairs[0].cloud).HasViewpoint());
  const CalibrationOutcome outcome = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const Errors errors = ErrorsOf(*outcome.solution, *dataset.cam_from_lidar_ground_truth);
  std::printf("viewpoints: %.2f mm, %.3f deg, NEES %.1f\n", errors.translation_m * 1e3,
              errors.rotation_rad * kRadToDeg, errors.nees);
  EXPECT_LT(errors.nees, 16.8);  // χ²(6), 99 %
  EXPECT_LT(errors.translation_m, 0.006);

  std::string summary;
  ASSERT_EQ(
      test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + (dir / "set").string() +
                           " --out " + (dir / "result.json").string() + " 2>&1",
                       &summary),
      0)
      << summary;
  EXPECT_NE(summary.find("LiDAR model: swept for all 12 pairs"), std::string::npos) << summary;
  EXPECT_NE(summary.find("along each return's own ray"), std::string::npos) << summary;
  const nlohmann::json result = nlohmann::json::parse(test::ReadFileBytes(dir / "result.json"));
  const nlohmann::json& noise = result.at("lidar_noise");
  EXPECT_EQ(noise.at("boards").get<int>(), 12) << noise.dump();
  EXPECT_NEAR(noise.at("range_sigma_m").at("median").get<double>(), 0.02, 0.002) << noise.dump();
  EXPECT_NE(result.at("lidar_model").at("meaning").get<std::string>().find("own ray"),
            std::string::npos);

  // The same scans without their viewpoints: the mirror is estimated from each scan
  // (core/lidar/swept_origin.h), and the result is the one the given rays give.
  sim.lidar_viewpoints = false;
  const Dataset bare = SimulateDataset(sim, dir / "bare");
  ASSERT_FALSE(LoadCloud(bare.pairs[0].cloud).HasViewpoint());
  const CalibrationOutcome estimated = CalibrateDataset(bare, PipelineOptions{});
  ASSERT_TRUE(estimated.solution) << estimated.failure;
  const PoseError apart =
      ComputePoseError(estimated.solution->cam_from_lidar, outcome.solution->cam_from_lidar);
  std::printf("estimated rays: %.3f mm, %.4f deg from the given ones\n", apart.translation_m * 1e3,
              apart.rotation_rad * kRadToDeg);
  EXPECT_LT(apart.translation_m, 0.0005);
  EXPECT_LT(apart.rotation_rad * kRadToDeg, 0.01);
  const std::string why = estimated.pairs[0].lidar->lidar_model.why;
  EXPECT_NE(why.find("cm from the stage's axis and"), std::string::npos) << why;
  EXPECT_NE(why.find("(estimated: the beams' angles"), std::string::npos) << why;
}

// Seedless = seeded on the swept laser and on board-only segments: the board is found in every
// cloud, and the result lands where the seeded one does (well within its σ).
TEST(LidarModels, WithoutSeedsTheResultIsTheSeededOne) {
  const fs::path dir = test::TempDir("lidar_models_seedless");
  SimOptions segments = SimPreset("default");
  segments.num_pairs = 10;
  segments.lidar_range_noise_m = 0.005;
  segments.board_only_clouds = true;
  for (const auto& [name, sim] : {std::pair{"swept", Swept(3)}, std::pair{"segments", segments}}) {
    SCOPED_TRACE(name);
    const Dataset dataset = SimulateDataset(sim, dir / name);
    const CalibrationOutcome seeded = CalibrateDataset(dataset, PipelineOptions{});
    Dataset unseeded = dataset;
    for (PairEntry& pair : unseeded.pairs) pair.lidar_seed.reset();
    const CalibrationOutcome detected = CalibrateDataset(unseeded, PipelineOptions{});
    ASSERT_TRUE(seeded.solution && detected.solution) << detected.failure;
    int accepted = 0;
    for (const PairFeatures& p : detected.pairs) {
      accepted += p.status == PairStatus::kAccepted;
      if (p.status != PairStatus::kAccepted)
        std::printf("%s %s: %s\n", name, p.id.c_str(), p.reason.c_str());
    }
    EXPECT_EQ(accepted, 10);
    const PoseError apart =
        ComputePoseError(detected.solution->cam_from_lidar, seeded.solution->cam_from_lidar);
    const PoseError error =
        ComputePoseError(detected.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
    const double sigma_t =
        TranslationStd(seeded.solution->covariance, seeded.solution->cam_from_lidar).norm();
    std::printf("%s: seedless vs seeded %.2f mm %.3f deg (seeded σ %.2f mm); error %.2f mm\n", name,
                apart.translation_m * 1e3, apart.rotation_rad * kRadToDeg, sigma_t * 1e3,
                error.translation_m * 1e3);
    EXPECT_LT(apart.translation_m, 0.5 * sigma_t);
  }
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// The real VLP-16 set's board-only clouds (the ACFR tool's segmentation, pcd/poseN_target.pcd)
// without their ring field, as several public sets ship the LiDAR side: every board is found
// without seeds and the result is the seeded one; the messages name what was seen (segments, the
// segment model, edges unused), never an attached board or a moved sensor.
TEST(LidarModels, RealBoardOnlySegmentsWithoutRings) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const fs::path acfr = shared / "datasets/acfr-vlp16-chessboard";
  const fs::path dir = test::TempDir("lidar_models_real_segments");
  Dataset dataset = LoadDataset(test::WriteAcfrManifest(acfr, dir));
  ASSERT_EQ(dataset.pairs.size(), 40u);
  for (PairEntry& pair : dataset.pairs) {
    const std::string stem = pair.cloud.stem().string();  // poseN_full
    LidarCloud cloud = LoadCloud(acfr / "pcd" / (stem.substr(0, stem.find('_')) + "_target.pcd"));
    cloud.ring.clear();
    pair.cloud = dir / (stem + "_segment.pcd");
    SavePcd(pair.cloud, cloud, PcdEncoding::kBinary);
  }
  const CalibrationOutcome seeded = CalibrateDataset(dataset, PipelineOptions{});
  Dataset unseeded = dataset;
  for (PairEntry& pair : unseeded.pairs) pair.lidar_seed.reset();
  const CalibrationOutcome detected = CalibrateDataset(unseeded, PipelineOptions{});
  ASSERT_TRUE(seeded.solution) << seeded.failure;
  ASSERT_TRUE(detected.solution) << detected.failure;
  for (const CalibrationOutcome* outcome : {&seeded, &detected}) {
    int accepted = 0;
    for (const PairFeatures& p : outcome->pairs) {
      accepted += p.status == PairStatus::kAccepted;
      EXPECT_EQ(p.reason.find("attached"), std::string::npos) << p.id << ": " << p.reason;
    }
    EXPECT_EQ(accepted, 40);
    EXPECT_TRUE(outcome->solution->converged) << outcome->solution->termination.Describe();
    EXPECT_EQ(
        DescribeLidarModel(*outcome).rfind("LiDAR model: segment for all 40 pairs (no rings", 0),
        0u)
        << DescribeLidarModel(*outcome);
    const ResidualCounts counts = CountResiduals(*outcome);
    EXPECT_EQ(counts.edge_pairs, 0);
    EXPECT_NE(counts.note.find("board edges unused"), std::string::npos) << counts.note;
  }
  EXPECT_NE(detected.background_note.find("the clouds hold segments, not scans"), std::string::npos)
      << detected.background_note;
  EXPECT_EQ(detected.background_note.find("moved"), std::string::npos);
  const PoseError apart =
      ComputePoseError(detected.solution->cam_from_lidar, seeded.solution->cam_from_lidar);
  const double sigma_t =
      TranslationStd(seeded.solution->covariance, seeded.solution->cam_from_lidar).norm();
  const PoseError to_reference =
      ComputePoseError(detected.solution->cam_from_lidar, test::AcfrReferenceCamFromLidar());
  std::printf(
      "real board-only segments: seedless vs seeded %.2f mm %.3f deg (σ %.2f mm); %.1f mm %.2f "
      "deg from the authors' reference\n",
      apart.translation_m * 1e3, apart.rotation_rad * kRadToDeg, sigma_t * 1e3,
      to_reference.translation_m * 1e3, to_reference.rotation_rad * kRadToDeg);
  EXPECT_LT(apart.translation_m, 0.5 * sigma_t);
  // σ honest at every pair count on the segments (issue 46): first k and 5 random subsets of 4-30
  // pairs, each within 3σ of the 40-pair result on every axis in at least 90 % of the cases. The
  // rings' range biases, found again in the returns' elevations, are what makes it so (without
  // them: 32 of 42).
  const SubsetCoverageOptions coverage;
  const SubsetCoverage subsets = RunSubsetCoverage(detected.pairs, PipelineOptions{}, coverage);
  std::printf("%s", FormatSubsetCoverage(subsets, coverage.coverage_sigmas).c_str());
  const int cases = static_cast<int>(subsets.cases.size());
  ASSERT_EQ(cases, 7 + 7 * 5);
  EXPECT_GE(subsets.covered, static_cast<int>(std::ceil(0.9 * cases)));
}

}  // namespace
}  // namespace calibench
