// A board waved in front of the rig, never still (core/sim/sim_wave.h): every LiDAR return at
// its own time, the camera's boards between its frames, and the offset between the two clocks
// estimated with the extrinsic (core/lidar_camera/time_offset.h) — against the same sweeps with
// the offset ignored, which is what every tool that pairs by nearest stamp does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/evaluation/crlb.h"
#include "core/geometry/geometry.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/lidar_camera/time_offset.h"
#include "core/report/calibration_report.h"
#include "core/report/report_html.h"
#include "core/results/export.h"
#include "core/results/result_file.h"
#include "core/session/calibration_job.h"
#include "core/sim/sim_wave.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// 10 s of a board waved at 0.4-0.5 m/s in front of a VLP-16 (10 Hz sweeps, each return at its
// own time) and a 1440 x 1080 camera at 10 Hz whose stamps are `camera_minus_lidar_s` off.
WavedDataset WaveAtOffset(const std::string& name, double camera_minus_lidar_s,
                          double duration_s = 10.0, std::uint64_t seed = 11) {
  WaveOptions wave;
  wave.rig.lidar = LidarModel::kVlp16;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.rig.seed = seed;
  wave.duration_s = duration_s;
  wave.camera_minus_lidar_s = camera_minus_lidar_s;
  return SimulateWavedDataset(wave, test::TempDir(name));
}

struct WavedCalibration {
  CalibrationOutcome outcome;
  PoseError error;
};

// The dataset's pairs extracted once, solved with the offset searched and with it fixed at 0.
std::pair<WavedCalibration, WavedCalibration> CalibrateWaved(const Dataset& dataset) {
  PipelineOptions options;
  options.threads = 2;
  const std::vector<const PairEntry*> selected = SelectedPairs(dataset, options);
  std::string note;
  const std::vector<PairFeatures> features =
      ExtractDatasetPairs(dataset, selected, options, {}, {}, &note);
  auto solve = [&](std::optional<double> fixed_offset_s) {
    PipelineOptions with = options;
    with.time_offset.fixed_s = fixed_offset_s;
    WavedCalibration c{SolveExtractedPairs(dataset, selected, features, with), {}};
    if (c.outcome.solution)
      c.error = ComputePoseError(c.outcome.solution->cam_from_lidar,
                                 *dataset.cam_from_lidar_ground_truth);
    return c;
  };
  return {solve(std::nullopt), solve(0.0)};
}

// The bound of the same sweeps: each board where it was at its returns' median time, seen by the
// camera there (the offset known), at the corner noise PnP's residuals measured.
CramerRaoBound BoundOfTheSameSweeps(const WavedDataset& waved, const Dataset& dataset,
                                    const CalibrationOutcome& outcome) {
  SimulationBoundInput bound_input;
  bound_input.pairs = waved.truth;
  bound_input.camera = dataset.camera;
  bound_input.board = dataset.target;
  bound_input.cam_from_lidar = *dataset.cam_from_lidar_ground_truth;
  bound_input.range_sigma_m = 0.01;
  double sigma_sum = 0.0;
  int posed = 0;
  for (const PairFeatures& p : outcome.pairs)
    for (const TimedObservation& frame : p.camera_track)
      sigma_sum += frame.observation.corner_sigma_px, ++posed;
  bound_input.corner_sigma_px = sigma_sum / std::max(posed, 1);
  return SimulationBound(bound_input);
}

// The error's largest ratio to its own σ, per camera axis of translation and of rotation.
double WorstAxisSigmas(const CalibrationOutcome& outcome, const Pose& truth) {
  const Pose& estimate = outcome.solution->cam_from_lidar;
  const Vec6 delta = LogSE3(estimate.inverse() * truth);  // right perturbation, as the covariance
  double worst = 0.0;
  for (int k = 0; k < 6; ++k)
    worst = std::max(worst, std::abs(delta(k)) / std::sqrt(outcome.solution->covariance(k, k)));
  return worst;
}

TEST(WavedBoard, TheOffsetBetweenTheClocksIsFoundWithTheExtrinsic) {
  for (const double offset : {0.040, -0.120}) {
    SCOPED_TRACE(offset);
    const WavedDataset waved = WaveAtOffset(offset > 0 ? "wave_late" : "wave_early", offset);
    EXPECT_GE(waved.median_speed_mps, 0.3);
    EXPECT_LE(waved.median_speed_mps, 0.6);
    ASSERT_GE(waved.dataset.pairs.size(), 60u) << "of " << waved.sweeps << " sweeps";
    // Each pair: its sweep's stamp, its returns' own times, every frame around it (0.25 s and
    // one frame either side of a 0.1 s sweep at 10 Hz: 7, fewer at the recording's ends).
    const Dataset dataset = LoadDataset(waved.dataset.manifest);
    const PairEntry& middle = dataset.pairs[dataset.pairs.size() / 2];
    ASSERT_TRUE(middle.lidar_stamp_ns);
    EXPECT_GE(middle.images.size(), 7u);
    EXPECT_TRUE(LoadCloud(middle.cloud).HasTime());

    const auto [found, ignored] = CalibrateWaved(dataset);
    ASSERT_TRUE(found.outcome.solution) << found.outcome.failure;
    const TimeOffsetEstimate& t = found.outcome.time_offset;
    ASSERT_TRUE(t.camera_minus_lidar_s) << t.why;
    const CramerRaoBound bound = BoundOfTheSameSweeps(waved, dataset, found.outcome);
    std::printf(
        "offset %+.0f ms: found %+.2f ms +- %.2f ms from %d moving pairs; extrinsic "
        "%.2f mm %.3f deg (%.1f sigma; bound %.2f mm %.3f deg)\n",
        offset * 1e3, *t.camera_minus_lidar_s * 1e3, t.std_s * 1e3, t.profiled_pairs,
        found.error.translation_m * 1e3, found.error.rotation_rad * kRadToDeg,
        WorstAxisSigmas(found.outcome, *dataset.cam_from_lidar_ground_truth),
        bound.translation_rms_m * 1e3, bound.rotation_rms_deg);
    EXPECT_NEAR(*t.camera_minus_lidar_s, offset, 0.002);
    EXPECT_LE(std::abs(*t.camera_minus_lidar_s - offset), 3 * t.std_s + 1e-4);
    EXPECT_GT(t.std_s, 0.0);
    EXPECT_LT(found.error.translation_m, 0.005);
    EXPECT_LT(found.error.rotation_rad * kRadToDeg, 0.2);
    EXPECT_LE(WorstAxisSigmas(found.outcome, *dataset.cam_from_lidar_ground_truth), 3.0);
    EXPECT_NE(FormatSummary(found.outcome).find("time offset: camera - LiDAR"), std::string::npos);
    // Into the result file and out to Kalibr with Kalibr's sign (t_lidar = t_cam + shift).
    const fs::path result = dataset.manifest.parent_path() / "result.json";
    WriteResult(result, found.outcome, SolverOptions{});
    const LoadedResult loaded = LoadResult(result);
    ASSERT_TRUE(loaded.camera_minus_lidar_s);
    EXPECT_DOUBLE_EQ(*loaded.camera_minus_lidar_s, *t.camera_minus_lidar_s);
    ExportFrames frames;
    frames.camera_minus_lidar_s = loaded.camera_minus_lidar_s;
    const std::string kalibr =
        ExportCalibration(ExportFormat::kKalibr, loaded.cam_from_source, frames, "result.json")
            .text;
    char shift[64];
    std::snprintf(shift, sizeof(shift), "timeshift_cam_lidar: %.9g\n", -*t.camera_minus_lidar_s);
    EXPECT_NE(kalibr.find(shift), std::string::npos) << kalibr;
    EXPECT_NE(ExportCalibration(ExportFormat::kUrdf, loaded.cam_from_source, frames, "result.json")
                  .text.find("Time offset: the camera's stamps minus the LiDAR's clock"),
              std::string::npos);

    // The workbench's and watch's job on the same folder finds the same clocks and pose.
    if (offset > 0) {
      Dataset setup = dataset;
      setup.pairs.clear();
      CalibrationJobOptions job_options;
      job_options.advise.pipeline.threads = 2;
      CalibrationJob job(setup, job_options);
      for (const PairEntry& pair : dataset.pairs) job.AddPair(pair);
      const CalibrationOutcome& in_job = job.Solve();
      ASSERT_TRUE(in_job.solution) << in_job.failure;
      ASSERT_TRUE(in_job.time_offset.camera_minus_lidar_s) << in_job.time_offset.why;
      // Not bit for bit on a moving capture, a difference not yet traced (one candidate: the
      // job's background model holds the first 40 clouds, CalibrationJobOptions::
      // max_background_clouds, `calibrate`'s all of them); the two agree within the offset's σ.
      const PoseError apart =
          ComputePoseError(in_job.solution->cam_from_lidar, found.outcome.solution->cam_from_lidar);
      std::printf("  the job: %+.2f ms, %.2f mm %.3f deg from calibrate's pose\n",
                  *in_job.time_offset.camera_minus_lidar_s * 1e3, apart.translation_m * 1e3,
                  apart.rotation_rad * kRadToDeg);
      EXPECT_NEAR(*in_job.time_offset.camera_minus_lidar_s, *t.camera_minus_lidar_s, t.std_s);
      // The workbench's solver panel says the clocks (the record's notes, as the summary).
      ASSERT_TRUE(job.CommitOutcome(/*own_step=*/true));
      const std::optional<SessionResult> said = job.record().Current().result;
      ASSERT_TRUE(said);
      EXPECT_NE(
          std::find(said->notes.begin(), said->notes.end(), DescribeTimeOffset(in_job.time_offset)),
          said->notes.end());
      EXPECT_LT(apart.translation_m, 0.002);
      EXPECT_LT(apart.rotation_rad * kRadToDeg, 0.05);
    }
    // The same sweeps with the offset ignored: each board taken where the camera's clock says.
    ASSERT_TRUE(ignored.outcome.solution) << ignored.outcome.failure;
    std::printf("  with the offset ignored (--time-offset 0): %.2f mm %.3f deg\n",
                ignored.error.translation_m * 1e3, ignored.error.rotation_rad * kRadToDeg);
    EXPECT_GT(ignored.error.translation_m, 3 * found.error.translation_m);
  }
}

// Issue 77's 40 s: several seeds of 40 s of waving, the extrinsic against the bound of the same
// sweeps. About 1 min a seed on 2 cores: run from scripts/wave_sweep.sh, not CI
// (--gtest_also_run_disabled_tests); CALIBENCH_WAVE_SEEDS="21 22 23" chooses the seeds.
TEST(WavedBoard, DISABLED_FortySecondsAgainstTheBoundOfTheSameSweeps) {
  const char* seeds_env = std::getenv("CALIBENCH_WAVE_SEEDS");
  std::istringstream seeds(seeds_env ? seeds_env : "21 22 23");
  for (std::uint64_t seed; seeds >> seed;) {
    SCOPED_TRACE(seed);
    const WavedDataset waved = WaveAtOffset("wave_40s_" + std::to_string(seed), 0.040, 40.0, seed);
    const Dataset dataset = LoadDataset(waved.dataset.manifest);
    const auto [found, ignored] = CalibrateWaved(dataset);
    ASSERT_TRUE(found.outcome.solution) << found.outcome.failure;
    const TimeOffsetEstimate& t = found.outcome.time_offset;
    ASSERT_TRUE(t.camera_minus_lidar_s) << t.why;
    const CramerRaoBound bound = BoundOfTheSameSweeps(waved, dataset, found.outcome);
    std::printf(
        "40 s, seed %llu: %+.2f +- %.2f ms; extrinsic %.3f mm %.4f deg (%.1f sigma); bound %.3f "
        "mm %.4f deg: %.2fx / %.2fx; offset ignored %.1f mm\n",
        static_cast<unsigned long long>(seed), *t.camera_minus_lidar_s * 1e3, t.std_s * 1e3,
        found.error.translation_m * 1e3, found.error.rotation_rad * kRadToDeg,
        WorstAxisSigmas(found.outcome, *dataset.cam_from_lidar_ground_truth),
        bound.translation_rms_m * 1e3, bound.rotation_rms_deg,
        found.error.translation_m / bound.translation_rms_m,
        found.error.rotation_rad * kRadToDeg / bound.rotation_rms_deg,
        ignored.error.translation_m * 1e3);
    EXPECT_NEAR(*t.camera_minus_lidar_s, 0.040, 0.002);
    EXPECT_LE(found.error.translation_m, 2 * bound.translation_rms_m);
    EXPECT_LE(found.error.rotation_rad * kRadToDeg, 2 * bound.rotation_rms_deg);
  }
}

// A Livox-class rosette (Mid-40: one beam through two prisms, its rays at their own times) waved
// in front of the camera: each 0.1 s frame a pair, the clocks found as for a spinning LiDAR; the
// report plots the planes' disagreement against the offset.
TEST(WavedBoard, ARosettesReturnsAtTheirOwnTimesTellTheOffset) {
  WaveOptions wave;
  wave.rig.lidar = LidarModel::kMid40;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.rig.seed = 13;
  wave.duration_s = 10.0;
  wave.across_m = 0.4;  // within the 38.4 deg circle
  wave.camera_minus_lidar_s = 0.040;
  const WavedDataset waved = SimulateWavedDataset(wave, test::TempDir("wave_mid40"));
  ASSERT_GE(waved.dataset.pairs.size(), 60u) << "of " << waved.sweeps << " frames";
  const Dataset dataset = LoadDataset(waved.dataset.manifest);
  const LidarCloud middle = LoadCloud(dataset.pairs[dataset.pairs.size() / 2].cloud);
  ASSERT_TRUE(middle.HasTime());
  EXPECT_FALSE(middle.HasRing());
  const auto [first, last] = std::minmax_element(middle.time_s.begin(), middle.time_s.end());
  EXPECT_GT(*last - *first, 0.09f);  // the frame's rays over its 0.1 s

  const auto [found, ignored] = CalibrateWaved(dataset);
  ASSERT_TRUE(found.outcome.solution) << found.outcome.failure;
  const TimeOffsetEstimate& t = found.outcome.time_offset;
  ASSERT_TRUE(t.camera_minus_lidar_s) << t.why;
  const CramerRaoBound bound = BoundOfTheSameSweeps(waved, dataset, found.outcome);
  std::printf(
      "Mid-40, +40 ms: found %+.2f ms +- %.2f ms from %d moving pairs; extrinsic %.2f mm %.3f "
      "deg (%.1f sigma; bound %.2f mm %.3f deg); offset ignored %.2f mm %.3f deg\n",
      *t.camera_minus_lidar_s * 1e3, t.std_s * 1e3, t.profiled_pairs,
      found.error.translation_m * 1e3, found.error.rotation_rad * kRadToDeg,
      WorstAxisSigmas(found.outcome, *dataset.cam_from_lidar_ground_truth),
      bound.translation_rms_m * 1e3, bound.rotation_rms_deg, ignored.error.translation_m * 1e3,
      ignored.error.rotation_rad * kRadToDeg);
  EXPECT_NEAR(*t.camera_minus_lidar_s, wave.camera_minus_lidar_s, 0.002);
  EXPECT_LE(std::abs(*t.camera_minus_lidar_s - wave.camera_minus_lidar_s), 3 * t.std_s + 1e-4);
  EXPECT_LT(found.error.translation_m, 0.01);
  EXPECT_LT(found.error.rotation_rad * kRadToDeg, 0.3);
  EXPECT_LE(WorstAxisSigmas(found.outcome, *dataset.cam_from_lidar_ground_truth), 3.0);
  ASSERT_TRUE(ignored.outcome.solution) << ignored.outcome.failure;
  EXPECT_GT(ignored.error.translation_m, 3 * found.error.translation_m);

  // The profile: every offset solved once, in order, across the window; lowest about the
  // estimate; the report's section and its plot's data.
  ASSERT_GE(t.profile_offsets_s.size(), 30u);
  EXPECT_TRUE(std::is_sorted(t.profile_offsets_s.begin(), t.profile_offsets_s.end()));
  EXPECT_NEAR(t.profile_offsets_s.front(), -0.25, 1e-9);
  EXPECT_NEAR(t.profile_offsets_s.back(), 0.25, 1e-9);
  const size_t lowest =
      std::min_element(t.profile_costs.begin(), t.profile_costs.end()) - t.profile_costs.begin();
  EXPECT_NEAR(t.profile_offsets_s[lowest], *t.camera_minus_lidar_s, 0.002);
  ReportOptions quick;
  quick.cross_validate = false;
  quick.sigma_history = false;
  const CalibrationReport report =
      AnalyseCalibration(dataset, found.outcome, PipelineOptions{}, quick);
  const std::string html = ReportHtml(
      report, {}, {}, LoadReportAssets(fs::path(CALIBENCH_SOURCE_DIR) / "assets/report"));
  EXPECT_NE(html.find("<canvas id=\"time-offset-profile\">"), std::string::npos);
  EXPECT_NE(html.find("time offset: camera - LiDAR +"), std::string::npos);
  EXPECT_NE(html.find("\"chi2_above_lowest\""), std::string::npos);
}

// Still holds are the special case of a slow trajectory: nothing to tell the clocks apart, said
// as such, and the result as it was.
TEST(WavedBoard, StillHoldsSayTheMotionCannotTellTheOffset) {
  SimOptions still;
  still.num_pairs = 12;
  still.seed = 3;
  const Dataset dataset = SimulateDataset(still, test::TempDir("wave_still_holds"));
  PipelineOptions options;
  options.threads = 2;
  const CalibrationOutcome outcome = CalibrateDataset(dataset, options);
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  EXPECT_FALSE(outcome.time_offset.camera_minus_lidar_s);
  EXPECT_EQ(outcome.time_offset.why,
            "every pair is a still hold (one image, or a board its frames saw still): the motion "
            "cannot tell the two clocks apart");
  const fs::path result = test::TempDir("wave_still_holds") / "result.json";
  WriteResult(result, outcome, options.solver);
  std::ifstream in(result);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("time_offset").is_null());
  EXPECT_EQ(j.at("time_offset_why"), outcome.time_offset.why);
}

}  // namespace
}  // namespace calibench
