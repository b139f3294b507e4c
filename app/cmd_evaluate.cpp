#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/dataset.h"
#include "core/result_io.h"

namespace calibench::app {
namespace {

void PrintError(const PoseError& error, const Mat6& covariance, const Pose& cam_from_lidar) {
  const Vec3 st = TranslationStd(covariance, cam_from_lidar) * 1000.0;
  const Vec3 sr = RotationStdDeg(covariance, cam_from_lidar);
  std::printf("error against ground truth: translation %.2f mm, rotation %.3f deg\n",
              error.translation_m * 1000.0, error.rotation_rad * 180.0 / M_PI);
  std::printf("reported std: translation %.2f mm, rotation %.3f deg (root of summed variances)\n",
              st.norm(), sr.norm());
}

}  // namespace

int RunEvaluate(int argc, char** argv) {
  // LRF results (cam_from_lrf) and the stereo-baseline check live in cmd_lrf.cpp.
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--stereo") return RunEvaluateLrf(argc, argv);
    if ((arg == "--dataset" || arg == "-d") && i + 1 < argc && IsLrfManifest(argv[i + 1]))
      return RunEvaluateLrf(argc, argv);
  }
  CLI::App app{"Score a calibench.result.v1 file against a dataset's ground_truth.",
               "calibench evaluate"};
  std::string result_path, dataset_path;
  double max_translation_mm = -1, max_rotation_deg = -1;
  app.add_option("--result,-r", result_path, "result.json")->required();
  app.add_option("--dataset,-d", dataset_path, "dataset with ground_truth.cam_from_lidar")
      ->required();
  app.add_option("--max-translation-mm", max_translation_mm, "fail (exit 5) above this error");
  app.add_option("--max-rotation-deg", max_rotation_deg, "fail (exit 5) above this error");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  const LoadedResult result = LoadResult(result_path);
  const Dataset dataset = LoadDataset(dataset_path);
  if (!dataset.cam_from_lidar_ground_truth) {
    std::fprintf(stderr, "calibench evaluate: %s has no ground_truth.cam_from_lidar\n",
                 dataset.manifest.string().c_str());
    return kInputError;
  }
  const PoseError error =
      ComputePoseError(result.cam_from_source, *dataset.cam_from_lidar_ground_truth);
  PrintError(error, result.covariance, result.cam_from_source);
  const bool too_far =
      (max_translation_mm >= 0 && error.translation_m * 1000 > max_translation_mm) ||
      (max_rotation_deg >= 0 && error.rotation_rad * 180 / M_PI > max_rotation_deg);
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
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
  options.threads = 2;
  CalibrationOutcome outcome;
  const int code = CalibrateAndReport(dataset, options, out_dir + "/result.json", &outcome);
  if (outcome.solution && dataset.cam_from_lidar_ground_truth)
    PrintError(
        ComputePoseError(outcome.solution->cam_from_lidar, *dataset.cam_from_lidar_ground_truth),
        outcome.solution->covariance, outcome.solution->cam_from_lidar);
  if (code != kOk) return code;
  // With a display the workbench opens on the demo; without one its views are rendered to PNG.
  const char* display = std::getenv("DISPLAY");
  if (!no_gui && display && *display) {
    std::printf("opening the workbench on %s (close the window to finish)\n",
                dataset.manifest.string().c_str());
    return RunGuiWindow(dataset.manifest.string(), "", 1600, 900, "", 0);
  }
  return RenderDemoViews(dataset.manifest.string(), out_dir);
}

}  // namespace calibench::app
