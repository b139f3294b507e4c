#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <set>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/io/dataset.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/session/job.h"
#include "core/session/lrf_calibration_job.h"
#include "core/session/session.h"

namespace calibench::app {

namespace {

// A rig (its folder or manifest): every camera, then the rig solve (core/lidar_camera/rig.h),
// each camera with the edits of its session among `sessions`; the summary printed, the rig's
// result written to out_path, its report to report_path.
int CalibrateRigDataset(const std::string& path, const std::vector<std::string>& sessions,
                        const PipelineOptions& options, const std::string& out_path,
                        const std::string& report_path) {
  const RigFolder rig = LoadRig(path);
  const RigOutcome outcome =
      CalibrateRig(rig, options, StderrProgress("extracted"), RigEditsOfSessions(rig, sessions));
  std::printf("%s", FormatRigSummary(outcome).c_str());
  if (outcome.joint && !out_path.empty()) {
    WriteRigResult(out_path, outcome);
    std::printf("wrote %s\n", out_path.c_str());
  }
  // Said as one camera's solve is: unreadable files, weak cameras, the error against the truth.
  const int code = SayVerdicts(CameraVerdicts(rig, outcome), outcome.camera_names, "calibrate",
                               "the rig " + path);
  if (!outcome.joint || report_path.empty()) return code;
  ReportRequest request;
  request.out_path = report_path;
  request.result_file = out_path;
  const int written = WriteReport(rig, outcome, options, request);
  return code != kOk ? code : written;
}

// One camera's dataset: its intrinsics first when `intrinsics_model` names a model (else its
// camera file must be there), the calibration written to request.result_file, the report to
// request.out_path (none when empty).
int CalibrateOneCamera(Dataset* dataset, const PairEdits& edits,
                       const std::string& intrinsics_model, const PipelineOptions& options,
                       const ReportRequest& request) {
  std::optional<IntrinsicsResult> intrinsics;
  if (!dataset->missing_camera_file.empty() && intrinsics_model.empty()) {
    std::fprintf(stderr,
                 "calibench calibrate: %s is missing: the camera's intrinsics go there (OpenCV "
                 "YAML, ROS camera_info or a Kalibr camchain); or pass --estimate-intrinsics to "
                 "estimate them from the pairs' images first\n",
                 dataset->missing_camera_file.c_str());
    return kInputError;
  }
  if (!intrinsics_model.empty()) {
    if (const int code =
            EstimateDatasetIntrinsics("calibrate", intrinsics_model, dataset, &intrinsics);
        code != kOk)
      return code;
  }
  const std::string& out_path = request.result_file;
  // With a report: its figures keep the pairs' files as the extraction reads them.
  ReportRequest report = request;
  CalibrationOutcome outcome;
  const int code =
      CalibrateAndReport(*dataset, KeepingInputsForViews(options, dataset->camera, &report),
                         out_path, &outcome, edits, intrinsics);
  if (report.out_path.empty() || !outcome.solution) return code;
  const RigFolder rig = RigOfOne(*dataset);
  const int written = WriteReport(rig, RigOutcomeOfOne(rig, std::move(outcome)), options, report);
  return code != kOk ? code : written;
}

// A 2D LRF dataset or session given to `calibrate`: the LRF method's job, solved as
// `lrf-calibrate` solves it, through the one Job interface (SolveAndSay). Only the flags both
// methods mean the same by apply; any other given is refused rather than ignored.
int CalibrateLrf(const CLI::App& app, const std::string& dataset_path, const std::string& session,
                 const PipelineOptions& lidar_camera, const std::string& out_path,
                 const std::string& report_path) {
  static const std::set<std::string> kShared = {"--dataset", "--session", "--out",
                                                "--report",  "--pairs",   "--threads"};
  for (const CLI::Option* option : app.get_options()) {
    if (option->count() == 0 || kShared.count(option->get_name())) continue;
    std::fprintf(stderr,
                 "calibench calibrate: %s is the LiDAR-camera method's, and %s is a 2D LRF %s: "
                 "give it --out, --report, --pairs or --threads only (`calibench lrf-calibrate` "
                 "has the LRF method's own flags)\n",
                 option->get_name().c_str(),
                 session.empty() ? dataset_path.c_str() : session.c_str(),
                 session.empty() ? "dataset" : "session");
    return kUsage;
  }
  LrfPipelineOptions options;
  options.threads = lidar_camera.threads;
  options.pair_ids = lidar_camera.pair_ids;
  std::string why;
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench calibrate: %s\n", why.c_str());
    return kUsage;
  }
  const std::unique_ptr<LrfCalibrationJob> job = OpenLrfJob(dataset_path, session, options);
  job->ExtractAll(StderrProgress("extracted"));
  const int code = SolveAndSay(*job, "calibrate", out_path);
  if (report_path.empty() || !job->outcome()->solution) return code;
  ReportRequest request;
  request.out_path = report_path;
  request.session_path = session;
  request.result_file = out_path;
  const int written = WriteLrfReport(*job, request);
  return code != kOk ? code : written;
}

}  // namespace

int RunCalibrate(int argc, char** argv) {
  CLI::App app{
      "Calibrate a 3D LiDAR to a camera from board planes (Ca²Lib plane-to-plane "
      "Gauss-Newton with a Huber kernel).",
      "calibench calibrate"};
  std::string dataset_path, out_path, report_path, camera;
  std::vector<std::string> sessions;
  AddDatasetOption(app, &dataset_path,
                   "a LiDAR-camera dataset, or a rig (a folder with cameras/<camera>.yaml, "
                   "images/<camera>/<stem>, clouds/<stem>; or a manifest naming \"cameras\"): "
                   "every camera, then the rig (calibench.rig.v1)");
  app.add_option(
      "--session", sessions,
      "a workbench session (calibench.session.json): its brushes, rejections and "
      "solver choices are used, so the result is the workbench's; its dataset unless "
      "--dataset is given. A rig takes one per camera (calibench.session.<camera>.json)");
  app.add_option("--camera", camera,
                 "with a rig: calibrate this camera alone (a calibench.result.v1, as for one "
                 "camera's dataset)");
  app.add_option("--out,-o", out_path, "result file (calibench.result.v1)");
  bool estimate_intrinsics = false;
  std::string intrinsics_model = "pinhole";
  app.add_flag("--estimate-intrinsics", estimate_intrinsics,
               "estimate the camera's intrinsics from the pairs' images first (as `calibench "
               "intrinsics`), instead of reading camera.yaml");
  app.add_option("--intrinsics-model", intrinsics_model,
                 "with --estimate-intrinsics: pinhole | fisheye")
      ->capture_default_str();
  app.add_option("--report", report_path,
                 "also write the HTML report (as `calibench report`) of this solve");
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  std::string why;
  if (!FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench calibrate: %s\n", why.c_str());
    return kUsage;
  }
  // Either method's dataset or session (core/session/job.h): a 2D LRF one runs the LRF job.
  if (JobKindOf(dataset_path, sessions.empty() ? "" : sessions.front()) == JobKind::kLrf) {
    if (sessions.size() > 1) {
      std::fprintf(stderr, "calibench calibrate: one --session for a 2D LRF dataset\n");
      return kUsage;
    }
    return CalibrateLrf(app, dataset_path, sessions.empty() ? "" : sessions.front(), flags.options,
                        out_path, report_path);
  }
  if (dataset_path.empty() && !sessions.empty())
    dataset_path = LoadSession(sessions.front()).dataset.string();
  if (dataset_path.empty()) {
    std::fprintf(stderr, "calibench calibrate: give --dataset or --session\n");
    return kUsage;
  }
  const bool rig = IsRig(dataset_path);
  if (rig && camera.empty())
    return CalibrateRigDataset(dataset_path, sessions, flags.options, out_path, report_path);
  if (sessions.size() > 1) {
    std::fprintf(stderr, "calibench calibrate: one --session for one camera (several: a rig's)\n");
    return kUsage;
  }
  if (!rig && !camera.empty()) {
    std::fprintf(stderr, "calibench calibrate: --camera: %s is not a rig\n", dataset_path.c_str());
    return kUsage;
  }
  const std::string session_path = sessions.empty() ? "" : sessions.front();
  const PairEdits edits = ApplySessionFlag(session_path, &dataset_path, &flags.options);
  Dataset dataset =
      rig ? LoadRigCamera(dataset_path, camera) : LoadDataset(dataset_path, CameraFile::kOptional);
  const std::string intrinsics = estimate_intrinsics ? intrinsics_model : "";
  ReportRequest request;
  request.out_path = report_path;
  request.session_path = session_path;
  request.result_file = out_path;  // the result file the solve writes and the report reads
  return CalibrateOneCamera(&dataset, edits, intrinsics, flags.options, request);
}

}  // namespace calibench::app
