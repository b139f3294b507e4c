#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/estimation/uncertainty.h"
#include "core/evaluation/crlb.h"
#include "core/geometry/geometry.h"
#include "core/io/dataset.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/result_io.h"
#include "core/results/export.h"
#include "core/results/reference.h"
#include "core/sim/sim.h"

namespace calibench::app {
namespace {

// `evaluate` of an LRF result or the stereo check (cmd_lrf.cpp), or `evaluate --sweep` (the Table 1
// protocol under the name issue 5 uses); nullopt for the 3D LiDAR evaluation itself.
std::optional<int> RunOtherEvaluation(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--stereo") return RunEvaluateLrf(argc, argv);
    if ((arg == "--dataset" || arg == "-d") && i + 1 < argc && IsLrfManifest(argv[i + 1]))
      return RunEvaluateLrf(argc, argv);
  }
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--subsets") return RunEvaluateSubsets(argc, argv);
    if (std::string(argv[i]) == "--sweep") {
      std::vector<char*> rest;
      for (int k = 0; k < argc; ++k)
        if (k != i) rest.push_back(argv[k]);
      return RunSweep(static_cast<int>(rest.size()), rest.data());
    }
  }
  return std::nullopt;
}

// Prints the Cramér–Rao bound of a simulated dataset into *bound; an exit code on failure.
int PrintCramerRaoBound(const Dataset& dataset, double corner_sigma_px,
                        std::optional<CramerRaoBound>* bound) {
  const SimOptions sim = SimOptionsFromDataset(dataset);
  if (!(sim.lidar_range_noise_m > 0)) {
    std::fprintf(stderr,
                 "calibench evaluate: %s: the simulation has no LiDAR range noise, so the "
                 "bound is zero\n",
                 dataset.manifest.string().c_str());
    return kInputError;
  }
  if (corner_sigma_px <= 0) corner_sigma_px = MeasureCornerSigma(dataset);
  if (!(corner_sigma_px > 0)) {
    std::fprintf(stderr,
                 "calibench evaluate: no board found to measure the corner noise; "
                 "give --corner-sigma-px\n");
    return kInputError;
  }
  const SimulationBoundInput input = MakeSimulationBoundInput(sim, corner_sigma_px);
  if (dataset.cam_from_lidar_ground_truth &&
      !dataset.cam_from_lidar_ground_truth->isApprox(input.cam_from_lidar, 1e-9)) {
    std::fprintf(stderr,
                 "calibench evaluate: %s: the simulation record does not reproduce "
                 "the ground truth\n",
                 dataset.manifest.string().c_str());
    return kInputError;
  }
  *bound = SimulationBound(input);
  const Vec3 st = TranslationStd((*bound)->covariance, input.cam_from_lidar) * 1000.0;
  std::printf(
      "Cramér–Rao bound (%zu pairs, range noise %.1f mm, corner noise %.3f px): translation "
      "%.2f mm RMS (std x/y/z %.2f / %.2f / %.2f mm, camera axes), rotation %.3f deg RMS\n",
      input.pairs.size(), sim.lidar_range_noise_m * 1e3, corner_sigma_px,
      (*bound)->translation_rms_m * 1e3, st.x(), st.y(), st.z(), (*bound)->rotation_rms_deg);
  return kOk;
}

// How a reference file is read: which of its frames is the camera, and in which convention.
struct ReferenceFlags {
  std::string path;
  std::string camera_frame = "optical";
  bool swap = false;
};

// `evaluate --reference`: the result against another calibration of the same rig, for real data
// without ground truth. The difference is also weighed by the result's own covariance (6-dof
// chi-square: about 6 when the reference lies where the result's uncertainty says the truth is).
int EvaluateAgainstReference(const LoadedResult& result, const ReferenceFlags& flags,
                             double max_translation_mm, double max_rotation_deg) {
  const std::optional<CameraFrame> camera_frame = ParseCameraFrame(flags.camera_frame);
  if (!camera_frame) {
    std::fprintf(stderr, "calibench evaluate: --reference-camera-frame must be optical or link\n");
    return kUsage;
  }
  ExportFrames frames;
  frames.camera_is_parent = flags.swap;
  frames.camera_frame = *camera_frame;
  std::string how;
  const Pose reference = ReadReferenceCamFromLidar(flags.path, frames, &how);
  std::printf("reference %s (%s; --reference-swap and --reference-camera-frame say otherwise)\n",
              flags.path.c_str(), how.c_str());
  const ReferenceDifference difference =
      CompareWithReference(result.cam_from_source, result.covariance, reference);
  const PoseError& error = difference.error;
  const Vec3& in_camera = difference.translation_in_camera_m;
  std::printf(
      "difference from the reference: translation %.2f mm (camera axes x/y/z %+.2f / %+.2f "
      "/ %+.2f mm), rotation %.3f deg\n",
      error.translation_m * 1e3, in_camera.x() * 1e3, in_camera.y() * 1e3, in_camera.z() * 1e3,
      error.rotation_rad * kRadToDeg);
  if (!difference.chi_square) {
    std::printf("(the result has no covariance: no weighing by its uncertainty)\n");
  } else {
    std::printf(
        "weighed by the result's covariance: chi-square %.1f on 6 dof (about 6 when the "
        "reference is where the result's uncertainty puts the truth; above 16.8 in 1%% "
        "of cases)\n",
        *difference.chi_square);
  }
  const bool too_far =
      (max_translation_mm >= 0 && error.translation_m * 1000 > max_translation_mm) ||
      (max_rotation_deg >= 0 && error.rotation_rad * kRadToDeg > max_rotation_deg);
  return too_far ? kAccuracyFailed : kOk;
}

}  // namespace

int RunEvaluate(int argc, char** argv) {
  if (const auto code = RunOtherEvaluation(argc, argv)) return *code;
  CLI::App app{
      "Score a calibench.result.v1 file against a dataset's ground_truth, and/or print "
      "the Cramér–Rao bound of a simulated dataset.",
      "calibench evaluate"};
  app.footer(
      "Other modes. LRF: with an LRF manifest as --dataset the result is cam_from_lrf "
      "(`calibench lrf-calibrate`); --stereo --right-result FILE checks the two depth cameras' "
      "results against the dataset's stereo baseline (the LRF paper's Section 4.3). "
      "--sweep runs the Table 1 sweep (`calibench sweep --help`). "
      "`calibench evaluate --stereo --help` shows the LRF flags.");
  std::string result_path, dataset_path;
  double max_translation_mm = -1, max_rotation_deg = -1, corner_sigma_px = 0;
  bool crlb = false, sweep = false;
  app.add_option("--result,-r", result_path, "result.json (optional with --crlb)");
  AddDatasetOption(app, &dataset_path, "a LiDAR-camera dataset with ground_truth.cam_from_lidar");
  ReferenceFlags reference;
  app.add_option("--reference", reference.path,
                 "compare --result with another calibration instead of ground truth: a result "
                 "JSON or any `calibench export` format (URDF, launch file, YAML, 4x4 text)");
  app.add_option("--reference-camera-frame", reference.camera_frame,
                 "the reference's camera frame: optical or link (REP 103)")
      ->capture_default_str();
  app.add_flag("--reference-swap", reference.swap,
               "in the reference the camera is the parent frame and the LiDAR the child");
  app.add_option("--max-translation-mm", max_translation_mm, "fail (exit 5) above this error");
  app.add_option("--max-rotation-deg", max_rotation_deg, "fail (exit 5) above this error");
  app.add_flag("--crlb", crlb,
               "print the Cramér–Rao bound of a simulated dataset (from its simulation record: "
               "range noise, poses) and, with --result, error / bound");
  app.add_option("--corner-sigma-px", corner_sigma_px,
                 "corner noise the bound assumes [px]; default: measured from the dataset's "
                 "PnP residuals");
  app.add_flag("--sweep", sweep, "run the Table 1 sweep instead (see `calibench sweep --help`)");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  if (result_path.empty() && !crlb) {
    std::fprintf(stderr, "calibench evaluate: --result is required (unless --crlb)\n");
    return kUsage;
  }
  if (!reference.path.empty())
    return EvaluateAgainstReference(LoadResult(result_path), reference, max_translation_mm,
                                    max_rotation_deg);
  if (dataset_path.empty()) {
    std::fprintf(stderr, "calibench evaluate: give --dataset (ground truth) or --reference\n");
    return kUsage;
  }
  const Dataset dataset = LoadDataset(dataset_path);
  std::optional<CramerRaoBound> bound;
  if (crlb) {
    const int code = PrintCramerRaoBound(dataset, corner_sigma_px, &bound);
    if (code != kOk) return code;
  }
  if (result_path.empty()) return kOk;
  const LoadedResult result = LoadResult(result_path);
  if (!dataset.cam_from_lidar_ground_truth) {
    std::fprintf(stderr, "calibench evaluate: %s has no ground_truth.cam_from_lidar\n",
                 dataset.manifest.string().c_str());
    return kInputError;
  }
  const PoseError error =
      ComputePoseError(result.cam_from_source, *dataset.cam_from_lidar_ground_truth);
  PrintErrorAgainstTruth(error, result.covariance, result.cam_from_source);
  if (bound)
    std::printf("error / bound: translation %.2f, rotation %.2f\n",
                error.translation_m / bound->translation_rms_m,
                error.rotation_rad * kRadToDeg / bound->rotation_rms_deg);
  const bool too_far =
      (max_translation_mm >= 0 && error.translation_m * 1000 > max_translation_mm) ||
      (max_rotation_deg >= 0 && error.rotation_rad * kRadToDeg > max_rotation_deg);
  return too_far ? kAccuracyFailed : kOk;
}

int RunDemo(int argc, char** argv) {
  CLI::App app{"Simulate the demo dataset, calibrate it and print the result and its error.",
               "calibench demo"};
  std::string out_dir = "out/demo";
  app.add_option("--out,-o", out_dir, "folder for the simulated dataset and result.json")
      ->capture_default_str();
  SimFlags sim_flags;
  sim_flags.preset = "demo";
  AddSimFlags(app, sim_flags);
  bool no_gui = false;
  app.add_flag("--no-gui", no_gui,
               "never open the workbench window (the views are rendered to PNG instead)");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  SimOptions sim;
  std::string why;
  if (!BuildSimOptions(sim_flags, &sim, &why)) {
    std::fprintf(stderr, "calibench demo: %s\n", why.c_str());
    return kUsage;
  }
  std::printf("simulating %d pairs (%s LiDAR) into %s ...\n", sim.num_pairs,
              LidarModelName(sim.lidar).c_str(), out_dir.c_str());
  const Dataset dataset = SimulateDataset(sim, out_dir);
  PipelineOptions options;
  CalibrationOutcome outcome;
  // The error against the simulation's truth is printed with the summary (SolveAndSay).
  const int code = CalibrateAndReport(dataset, options, out_dir + "/result.json", &outcome);
  if (code != kOk) return code;
  // With a display the workbench opens on the demo; without one its views are rendered to PNG.
  const char* display = std::getenv("DISPLAY");
  if (!no_gui && display && *display) {
    std::printf("opening the workbench on %s (close the window to finish)\n",
                dataset.manifest.string().c_str());
    return RunGuiWindow(dataset.manifest.string(), "", 1600, 900, "");
  }
  return RenderDemoViews(dataset.manifest.string(), out_dir);
}

}  // namespace calibench::app
