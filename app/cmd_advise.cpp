// `calibench advise`: where a capture stands against the user's goal and where to hold the board
// next (core/guidance).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "app/pipeline_flags.h"
#include "core/guidance/advise.h"
#include "core/guidance/lrf_meter.h"
#include "core/io/dataset.h"
#include "core/io/rig_folder.h"
#include "core/lrf_data/dataset.h"
#include "core/session/calibration_job.h"
#include "core/session/job.h"

namespace calibench::app {

namespace {

// The LiDAR-camera dataset's advice (with --estimate-intrinsics, its camera from its images
// first), printed as text or one JSON object.
int AdviseLidarCamera(const std::string& dataset_path, const AdviseOptions& options,
                      const std::string& intrinsics_model, bool json, MachineStdout& out) {
  Dataset dataset = LoadDataset(
      dataset_path, options.estimate_intrinsics ? CameraFile::kOptional : CameraFile::kRequired);
  if (options.estimate_intrinsics) {
    std::optional<IntrinsicsResult> first;
    if (const int code = EstimateDatasetIntrinsics("advise", intrinsics_model, &dataset, &first,
                                                   json ? stderr : stdout);
        code != kOk)
      return code;
  }
  // The job every front end runs (core/session/calibration_job.h), all pairs at once.
  CalibrationJobOptions job_options;
  job_options.advise = options;
  CalibrationJob job(dataset, job_options, {},
                     {.detected = StderrProgress("extracted"), .iteration = {}});
  job.DetectAll();
  bool input_error = false;
  for (const PairFeatures& p : job.Solve().pairs) input_error |= p.input_error;
  const CaptureAdvice& advice = job.Advise();
  if (json)
    out.Print(CaptureAdviceJson(advice));
  else
    std::printf("%s", FormatCaptureAdvice(advice).c_str());
  if (input_error) {
    std::fprintf(stderr, "calibench advise: some pair files of %s could not be read (see above)\n",
                 dataset.manifest.string().c_str());
    return kInputError;
  }
  return kOk;
}

// A rig: every camera's advice (its own capture against the goal, where to hold the board next
// for it), and whether every camera is done; text, or one JSON object {"cameras": {"<camera>":
// advice}, "done"}.
int AdviseRig(const std::string& rig_path, const AdviseOptions& options, bool json,
              MachineStdout& out) {
  const RigFolder rig = LoadRig(rig_path);
  nlohmann::json cameras = nlohmann::json::object();
  bool all_done = true, input_error = false;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    CalibrationJobOptions job_options;
    job_options.advise = options;
    CalibrationJob job(rig.cameras[c], job_options, {},
                       {.detected = StderrProgress("extracted"), .iteration = {}});
    job.DetectAll();
    for (const PairFeatures& p : job.Solve().pairs) input_error |= p.input_error;
    const CaptureAdvice& advice = job.Advise();
    all_done = all_done && advice.state && advice.state->done;
    if (json)
      cameras[rig.camera_names[c]] = nlohmann::json::parse(CaptureAdviceJson(advice));
    else
      std::printf("camera %s:\n%s\n", rig.camera_names[c].c_str(),
                  FormatCaptureAdvice(advice).c_str());
  }
  if (json)
    out.Print(nlohmann::json({{"cameras", cameras}, {"done", all_done}}).dump());
  else
    std::printf("rig: %s\n", all_done ? "DONE: every camera's sigma is under the goal and trusted"
                                      : "not done: see the cameras above");
  if (input_error) {
    std::fprintf(stderr, "calibench advise: some pair files of %s could not be read (see above)\n",
                 rig_path.c_str());
    return kInputError;
  }
  return kOk;
}

// An LRF dataset's advice: Algorithm 1's meter (core/guidance/lrf_meter.h).
int AdviseLrf(const std::string& dataset_path, AdviseOptions options, double lrf_threshold_mm,
              int threads, bool json, MachineStdout& out) {
  std::string why;
  if (!options.goal.Check(&why) || !options.stop.Check(&why) || !(lrf_threshold_mm > 0)) {
    if (why.empty()) why = "--error-threshold-mm must be > 0";
    std::fprintf(stderr, "calibench advise: %s\n", why.c_str());
    return kUsage;
  }
  const LrfDataset lrf = LoadLrfDataset(dataset_path);
  LrfPipelineOptions lrf_options;
  lrf_options.threads = threads;
  lrf_options.adaptive_error_threshold_m = lrf_threshold_mm * 1e-3;
  const LrfCalibrationOutcome outcome =
      CalibrateLrfDataset(lrf, lrf_options, StderrProgress("extracted"));
  // Algorithm 1's check stands in for the jackknife's, which is what asks for 8 pairs.
  StopRuleOptions lrf_stop = options.stop;
  lrf_stop.min_pairs = 4;
  const LrfCaptureAdvice advice =
      AdviseLrfCapture(outcome, lrf_options.adaptive_error_threshold_m, options.goal, lrf_stop);
  if (json)
    out.Print(LrfCaptureAdviceJson(advice));
  else
    std::printf("%s", FormatLrfCaptureAdvice(advice).c_str());
  return kOk;
}

}  // namespace

int RunAdvise(int argc, char** argv) {
  CLI::App app{
      "Say whether the dataset's poses are enough for the goal (1σ per axis, with a σ that "
      "can be trusted) and, if not, where to hold the board next.",
      "calibench advise"};
  std::string dataset_path;
  AdviseOptions options;
  bool json = false;
  AddDatasetOption(app, &dataset_path,
                   "a LiDAR-camera or 2D LRF dataset, or a rig (every camera against the goal)")
      ->required();
  AddGoalFlags(app, &options);
  app.add_option("--min-distance", options.min_distance_m,
                 "nearest usable board distance from the camera [m] (default: from the data)");
  app.add_option("--max-distance", options.max_distance_m,
                 "farthest usable board distance from the camera [m] (default: from the data)");
  app.add_flag("--json", json, "print exactly one JSON object on stdout");
  std::string intrinsics_model = "pinhole";
  app.add_flag("--estimate-intrinsics", options.estimate_intrinsics,
               "the camera's intrinsics are being calibrated from these pairs too (no camera "
               "file needed): the meter includes them (sigma, RMS, coverage; done only once they "
               "are good) and the next pose also puts corners where the image has none");
  app.add_option("--intrinsics-model", intrinsics_model,
                 "with --estimate-intrinsics: pinhole | fisheye")
      ->capture_default_str();
  double lrf_threshold_mm = 10.0;
  app.add_option("--error-threshold-mm", lrf_threshold_mm,
                 "LRF datasets: Algorithm 1's threshold on the newest observation's Eq. (12) "
                 "error [mm]; σ counts as final once it is reached")
      ->capture_default_str();
  PipelineFlags flags;
  AddPipelineFlags(app, flags, /*with_selection=*/true);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  std::string why;
  if (!FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench advise: %s\n", why.c_str());
    return kUsage;
  }
  options.pipeline = flags.options;
  MachineStdout out(json);  // from here on, only the JSON object reaches stdout
  if (JobKindOf(dataset_path, "") == JobKind::kLrf)
    return AdviseLrf(dataset_path, options, lrf_threshold_mm, flags.options.threads, json, out);
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench advise: %s\n", why.c_str());
    return kUsage;
  }
  if (IsRig(dataset_path)) {
    if (options.estimate_intrinsics) {
      std::fprintf(stderr,
                   "calibench advise: --estimate-intrinsics takes one camera; a rig's cameras "
                   "bring their files (cameras/<camera>.yaml)\n");
      return kUsage;
    }
    return AdviseRig(dataset_path, options, json, out);
  }
  return AdviseLidarCamera(dataset_path, options, intrinsics_model, json, out);
}

}  // namespace calibench::app
