// The 2D LRF commands: `lrf-calibrate`, `simulate --kind lrf`, and the LRF side of `evaluate`
// (ground truth and the paper's stereo-baseline check, Section 4.3).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/evaluation/lrf_sweep.h"
#include "core/io/dataset_source.h"
#include "core/lidar_camera/result_io.h"
#include "core/lrf/pipeline.h"
#include "core/lrf/result_io.h"
#include "core/session/lrf_calibration_job.h"
#include "core/sim/lrf_sim.h"

namespace calibench::app {
namespace {

std::vector<std::string> SplitIds(const std::string& text) {
  std::vector<std::string> ids;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) ids.push_back(item);
  return ids;
}

void PrintPoseError(const char* what, const Pose& estimate, const Pose& reference) {
  const PoseError e = ComputePoseError(estimate, reference);
  std::printf("%s: translation %.2f mm, rotation %.3f deg\n", what, e.translation_m * 1e3,
              e.rotation_rad * kRadToDeg);
}

}  // namespace

bool IsLrfManifest(const std::string& path) {
  std::string ignored;
  const auto source = RecogniseDataset(path, &ignored);
  return source && source->kind == DatasetKind::kLrf;
}

int RunLrfCalibrate(int argc, char** argv) {
  CLI::App app{
      "Calibrate a 2D laser rangefinder to a depth camera (three-face target, point-on-line "
      "constraints) or to an RGB camera (checkerboard, Zhang & Pless); writes "
      "calibench.result.v1 with cam_from_lrf.",
      "calibench lrf-calibrate"};
  std::string dataset_path, session_path, out_path, method = "refined", pairs_text;
  LrfPipelineOptions options;
  AddDatasetOption(app, &dataset_path, "a 2D LRF dataset (calibench.lrf-dataset.v1)");
  app.add_option("--session", session_path,
                 "an LRF workbench session (calibench.lrf-session.json beside the manifest): its "
                 "rejections and method are used, so the result is the workbench's; its dataset "
                 "unless --dataset is given");
  app.add_option("--out,-o", out_path, "result file (calibench.result.v1)");
  app.add_option("--method", method,
                 "refined (SE(3) Gauss-Newton over every scan point, seeded by paper-linear) | "
                 "paper-linear (Eq. (9)-(11))")
      ->capture_default_str();
  app.add_option("--error-threshold", options.adaptive_error_threshold_m,
                 "Algorithm 1: add observations in order until the newest one's Eq. (12) "
                 "corner-to-line error is below this [m]; 0 = use all")
      ->capture_default_str();
  app.add_option("--huber-delta", options.solver.huber_delta_m,
                 "Huber threshold on the point-to-plane distance [m]")
      ->capture_default_str();
  app.add_option("--pairs", pairs_text, "comma-separated pair ids (default: all)");
  app.add_option(
         "--threads", options.threads,
         "workers (default: this machine's hardware threads; the result does not depend on it)")
      ->capture_default_str();
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  const auto parsed = ParseLrfMethod(method);
  if (!parsed) {
    std::fprintf(stderr,
                 "calibench lrf-calibrate: --method must be refined or paper-linear, "
                 "not '%s'\n",
                 method.c_str());
    return kUsage;
  }
  options.solver.method = *parsed;
  options.pair_ids = SplitIds(pairs_text);
  std::string why;
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench lrf-calibrate: %s\n", why.c_str());
    return kUsage;
  }
  if (dataset_path.empty() && session_path.empty()) {
    std::fprintf(stderr, "calibench lrf-calibrate: give --dataset or --session\n");
    return kUsage;
  }
  // The job the LRF workbench runs (core/session/lrf_calibration_job.h), all pairs at once.
  const std::unique_ptr<LrfCalibrationJob> job = OpenLrfJob(dataset_path, session_path, options);
  if (app.count("--method") && job->options().solver.method != *parsed) {
    std::fprintf(stderr, "calibench lrf-calibrate: %s solves with %s; --method %s disagrees\n",
                 session_path.c_str(), LrfMethodName(job->options().solver.method).c_str(),
                 method.c_str());
    return kUsage;
  }
  job->ExtractAll(StderrProgress("extracted"));
  return SolveAndSay(*job, "lrf-calibrate", out_path);
}

int RunSimulateLrf(int argc, char** argv) {
  CLI::App app{
      "Write a synthetic 2D LRF + depth camera dataset (calibench.lrf-dataset.v1: scan JSON, "
      "16-bit depth PNG) with ground truth.",
      "calibench simulate --kind lrf"};
  std::string out_dir, preset = "paper", kind;
  int observations = 0;
  double range_noise = -1, disparity_noise = -1, min_distance = 0, max_distance = 0;
  std::uint64_t seed = 1;
  bool stereo = false, no_clutter = false;
  app.add_option("--kind", kind, "lrf")->required();
  app.add_option("--out,-o", out_dir, "output folder")->required();
  app.add_option("--preset", preset, "paper (R2000 + ZED-like) | ideal (noise-free)")
      ->capture_default_str();
  app.add_option("--observations", observations, "number of target poses (default 20)");
  app.add_option("--range-noise", range_noise, "LRF range noise sigma [m] (paper: 0.0125)");
  app.add_option("--disparity-noise", disparity_noise, "depth camera disparity noise sigma [px]");
  app.add_option("--min-distance", min_distance, "closest target distance [m]");
  app.add_option("--max-distance", max_distance, "farthest target distance [m]");
  app.add_option("--seed", seed, "random seed")->capture_default_str();
  app.add_flag("--stereo", stereo,
               "also a right depth camera 0.12 m to the right (right.json), for "
               "`evaluate --stereo`");
  app.add_flag("--no-clutter", no_clutter, "no walls or floor");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  if (kind != "lrf") {
    std::fprintf(stderr, "calibench simulate: --kind must be lrf (or absent for the 3D LiDAR)\n");
    return kUsage;
  }
  auto options = LrfSimPreset(preset);
  if (!options) {
    std::fprintf(stderr, "calibench simulate: unknown LRF preset '%s' (paper, ideal)\n",
                 preset.c_str());
    return kUsage;
  }
  if (observations > 0) options->observations = observations;
  if (range_noise >= 0) options->lrf.range_noise_m = range_noise;
  if (disparity_noise >= 0) options->depth.disparity_noise_px = disparity_noise;
  if (min_distance > 0) options->target_distance_min_m = min_distance;
  if (max_distance > 0) options->target_distance_max_m = max_distance;
  options->seed = seed;
  options->stereo = stereo;
  if (no_clutter) options->clutter = false;
  std::string why;
  if (!options->Check(&why)) {
    std::fprintf(stderr, "calibench simulate: %s\n", why.c_str());
    return kUsage;
  }
  const auto manifest = WriteLrfSimDataset(*options, out_dir);
  std::printf("wrote %d LRF observations to %s%s\n", options->observations,
              manifest.string().c_str(), stereo ? " (and right.json)" : "");
  return kOk;
}

int RunEvaluateLrf(int argc, char** argv) {
  CLI::App app{
      "Score an LRF result against an LRF dataset's ground truth, or check the stereo "
      "baseline (calibrate to the left and to the right camera, compose, compare with "
      "the known baseline: the paper's Section 4.3).",
      "calibench evaluate (LRF)"};
  std::string result_path, right_result_path, dataset_path;
  double max_translation_mm = -1, max_rotation_deg = -1;
  bool stereo = false;
  app.add_option("--result,-r", result_path, "result.json (the left camera's with --stereo)")
      ->required();
  app.add_option("--right-result", right_result_path, "--stereo: the right camera's result");
  AddDatasetOption(app, &dataset_path,
                   "a 2D LRF dataset with ground_truth.cam_from_lrf (with --stereo: one carrying "
                   "stereo.right_from_left)")
      ->required();
  app.add_flag("--stereo", stereo, "the stereo-baseline check");
  app.add_option("--max-translation-mm", max_translation_mm, "fail (exit 5) above this error");
  app.add_option("--max-rotation-deg", max_rotation_deg, "fail (exit 5) above this error");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  const LrfDataset dataset = LoadLrfDataset(dataset_path);
  const LoadedResult left = LoadResult(result_path);
  Pose estimate, reference;
  if (stereo) {
    if (right_result_path.empty()) {
      std::fprintf(stderr, "calibench evaluate: --stereo needs --right-result\n");
      return kUsage;
    }
    if (!dataset.right_from_left) {
      std::fprintf(stderr, "calibench evaluate: %s has no stereo.right_from_left\n",
                   dataset.manifest.string().c_str());
      return kInputError;
    }
    const LoadedResult right = LoadResult(right_result_path);
    // right_from_left = right_from_lrf · (left_from_lrf)⁻¹.
    estimate = right.cam_from_source * left.cam_from_source.inverse();
    reference = *dataset.right_from_left;
    std::printf(
        "baseline (right camera in the left frame): estimated [%.1f, %.1f, %.1f] mm, "
        "known [%.1f, %.1f, %.1f] mm\n",
        estimate.inverse().translation().x() * 1e3, estimate.inverse().translation().y() * 1e3,
        estimate.inverse().translation().z() * 1e3, reference.inverse().translation().x() * 1e3,
        reference.inverse().translation().y() * 1e3, reference.inverse().translation().z() * 1e3);
    PrintPoseError("stereo baseline error", estimate, reference);
  } else {
    if (!dataset.cam_from_lrf_ground_truth) {
      std::fprintf(stderr, "calibench evaluate: %s has no ground_truth.cam_from_lrf\n",
                   dataset.manifest.string().c_str());
      return kInputError;
    }
    estimate = left.cam_from_source;
    reference = *dataset.cam_from_lrf_ground_truth;
    PrintPoseError("error against ground truth", estimate, reference);
  }
  const PoseError e = ComputePoseError(estimate, reference);
  const bool too_far = (max_translation_mm >= 0 && e.translation_m * 1e3 > max_translation_mm) ||
                       (max_rotation_deg >= 0 && e.rotation_rad * kRadToDeg > max_rotation_deg);
  return too_far ? kAccuracyFailed : kOk;
}

int RunSweepLrf(int argc, char** argv) {
  CLI::App app{
      "Errors against the number of observations for the LRF methods on simulated data "
      "(the paper's Section 4.3 protocol against ground truth).",
      "calibench sweep --kind lrf"};
  std::string kind, sizes_text = "2,3,4,6,8,10,15,20", table_path, preset = "paper";
  LrfSweepOptions options;
  app.add_option("--kind", kind, "lrf")->required();
  app.add_option("--sizes", sizes_text, "numbers of observations")->capture_default_str();
  app.add_option("--seeds", options.seeds, "independent simulations per size")
      ->capture_default_str();
  app.add_option("--threads", options.pipeline.threads,
                 "workers, one seed each (default: this machine's hardware threads; the table does "
                 "not depend on it)")
      ->capture_default_str();
  app.add_option("--preset", preset, "paper | ideal")->capture_default_str();
  app.add_option("--table", table_path, "also write the markdown table here");
  DepthFeatureOptions& depth = options.pipeline.depth;
  app.add_option("--depth-normals", depth.normals,
                 "grid (ours: PCA over grid neighbours, depth-dependent window) | pcl (PCL's "
                 "IntegralImageNormalEstimation)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, DepthNormalMethod>{
          {"grid", DepthNormalMethod::kGridPca}, {"pcl", DepthNormalMethod::kPclIntegralImage}}))
      ->default_str("grid");
  app.add_option(
         "--depth-plane-search", depth.plane_search,
         "ours (one point and its normal per draw) | pcl (PCL's SACSegmentationFromNormals)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, DepthPlaneSearch>{{"ours", DepthPlaneSearch::kPointNormalRansac},
                                                  {"pcl", DepthPlaneSearch::kPclSacNormalPlane}}))
      ->default_str("ours");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  auto sim = LrfSimPreset(preset);
  if (kind != "lrf" || !sim || options.seeds < 1) {
    std::fprintf(stderr, "calibench sweep: --kind lrf, --preset paper|ideal, --seeds >= 1\n");
    return kUsage;
  }
  options.sim = *sim;
  options.sizes.clear();
  for (const std::string& item : SplitIds(sizes_text)) {
    try {
      options.sizes.push_back(std::stoi(item));
    } catch (const std::exception&) {
      options.sizes.clear();
      break;
    }
  }
  if (options.sizes.empty() || *std::min_element(options.sizes.begin(), options.sizes.end()) < 2) {
    std::fprintf(stderr, "calibench sweep: --sizes takes comma-separated integers >= 2\n");
    return kUsage;
  }
  const LrfSweepResult result = RunLrfSweep(
      options, [](int done, int total) { std::fprintf(stderr, "seed %d of %d\n", done, total); });
  const int code =
      PrintAndWriteTable(FormatLrfSweepTable(result), table_path, "calibench sweep --kind lrf");
  std::printf("feature extraction failed on %d of %d simulated observations\n",
              result.observations_failed, result.observations_total);
  return code;
}

}  // namespace calibench::app
