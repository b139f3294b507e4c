// calibench report (and calibrate --report): the pipeline's outcome analysed (core/report), the
// workbench's views drawn headless, one self-contained HTML file written atomically.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/base/atomic_file.h"
#include "core/io/assets.h"
#include "core/io/dataset.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/lrf_data/dataset.h"
#include "core/report/lrf_report.h"
#include "core/report/resolve_notes.h"
#include "core/results/result_file.h"
#include "core/session/job.h"
#include "core/session/lrf_calibration_job.h"
#include "core/session/session.h"
#include "ui/lidar_camera/report_figures.h"

namespace calibench::app {

namespace {

namespace fs = std::filesystem;

std::string NowUtc() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace

PipelineOptions KeepingInputsForViews(const PipelineOptions& options, const CameraModel& camera,
                                      ReportRequest* request) {
  PipelineOptions keeping = options;
  if (request->out_path.empty() || !request->renders) return keeping;
  request->kept_inputs = std::make_shared<ui::KeptPairInputs>(camera, ui::ReportFigureOptions{});
  keeping.on_pair_inputs = request->kept_inputs->Keeper();
  return keeping;
}

namespace {

// Each camera's analysis and views (none for the rest once one could not be drawn: no OpenGL).
// *why: what kept views out, "" when none was.
std::vector<RigCameraReport> AnalyseCameras(const RigFolder& rig, const RigOutcome& outcome,
                                            const PipelineOptions& options,
                                            const ReportRequest& request, std::string* why) {
  std::vector<RigCameraReport> cameras;
  bool drawing = request.renders;
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    RigCameraReport camera;
    camera.name = outcome.camera_names[c];
    camera.prefix = "camera" + std::to_string(c) + "-";  // ids stay valid whatever the name
    camera.report = AnalyseCalibration(rig.cameras[c], outcome.single[c], options, request.options);
    if (drawing) {
      ui::ReportFigureOptions figure_options;
      figure_options.threads = options.threads;
      std::string missing;
      // The kept inputs are one camera's (KeepingInputsForViews): a rig reads its files again.
      const ui::KeptPairInputs* kept = outcome.Several() ? nullptr : request.kept_inputs.get();
      camera.figures = ui::DrawReportFigures(rig, outcome, c, figure_options, kept, &missing);
      if (!missing.empty() && why->empty()) *why = missing;
      drawing = missing.empty() || !camera.figures.empty();
    }
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

// What the views' absence or gaps say in the report and on stderr.
void NoteViews(const std::vector<RigCameraReport>& cameras, const std::string& why,
               ReportProvenance* provenance) {
  if (why.empty()) return;
  const bool none = std::all_of(cameras.begin(), cameras.end(),
                                [](const RigCameraReport& c) { return c.figures.empty(); });
  if (none) {
    std::fprintf(stderr, "calibench report: %s; the report has no views\n", why.c_str());
    provenance->notes.push_back("No views: " + why + ".");
  } else {
    std::fprintf(stderr, "calibench report: %s\n", why.c_str());
    provenance->notes.push_back(why + ".");
  }
}

void PrintWritten(const std::string& path, const std::vector<RigCameraReport>& cameras) {
  auto verdict = [](const CalibrationReport& report) {
    return report.cross_validation ? report.cross_validation->verdict : std::string();
  };
  if (cameras.size() == 1) {
    const CalibrationReport& report = cameras.front().report;
    std::printf("wrote %s (%zu pairs, %zu views)%s%s\n", path.c_str(), report.pairs.size(),
                cameras.front().figures.size(), report.cross_validation ? ": " : "",
                verdict(report).c_str());
    if (!report.distrust.empty()) std::printf("%s\n", report.distrust.c_str());
    return;
  }
  std::printf("wrote %s (a rig of %zu cameras", path.c_str(), cameras.size());
  for (const RigCameraReport& camera : cameras)
    std::printf("; %s: %zu pairs, %zu views%s%s", camera.name.c_str(), camera.report.pairs.size(),
                camera.figures.size(), camera.report.cross_validation ? ", " : "",
                verdict(camera.report).c_str());
  std::printf(")\n");
}

}  // namespace

int WriteReport(const RigFolder& rig, const RigOutcome& outcome, const PipelineOptions& options,
                const ReportRequest& request) {
  CALIBENCH_CHECK(outcome.joint.has_value() && !(outcome.Several() && request.check));
  ReportProvenance provenance;
  const std::string data = rig.folder.string();
  provenance.source =
      outcome.Several()
          ? data + " (a rig of " + std::to_string(outcome.camera_names.size()) + " cameras)"
      : request.session_path.empty() ? data
                                     : request.session_path + " (session of " + data + ")";
  provenance.result_file = request.result_file;
  provenance.created_utc = NowUtc();
  provenance.calibench_version = CALIBENCH_VERSION;
  provenance.notes = request.notes;
  std::string why;
  const std::vector<RigCameraReport> cameras = AnalyseCameras(rig, outcome, options, request, &why);
  NoteViews(cameras, why, &provenance);
  const ReportAssets assets = LoadReportAssets(FindAsset("report"));
  if (outcome.Several()) {
    WriteFileAtomically(request.out_path,
                        RigReportHtml(SummarizeRigOutcome(outcome), cameras, provenance, assets));
  } else {
    const std::string sections = request.check ? TargetlessCheckHtml(*request.check) : "";
    WriteFileAtomically(request.out_path, ReportHtml(cameras.front().report, provenance,
                                                     cameras.front().figures, assets, sections));
  }
  PrintWritten(request.out_path, cameras);
  return kOk;
}

namespace {

// The data `report` re-solves, as RunReport's flags name it: a rig (with the session's edits for
// its camera), or one camera's dataset as a rig of one (with its session's edits and options).
// kOk, or the exit code with the error printed.
int OpenReportedData(const std::string& result_path, std::string session_path,
                     std::string dataset_path, PipelineOptions* options, ReportRequest* request,
                     RigFolder* rig, RigEdits* edits) {
  if (IsRigResultFile(result_path) || (!dataset_path.empty() && IsRig(dataset_path))) {
    if (dataset_path.empty()) {
      std::fprintf(stderr, "calibench report: a rig result: give --dataset <the rig>\n");
      return kUsage;
    }
    *rig = LoadRig(dataset_path);
    if (!session_path.empty()) *edits = RigEditsOfSessions(*rig, {session_path});
    return kOk;
  }
  if (session_path.empty() && IsSessionFile(result_path)) session_path = result_path;
  const PairEdits camera_edits = ApplySessionFlag(session_path, &dataset_path, options);
  if (dataset_path.empty()) {
    std::fprintf(stderr, "calibench report: give --dataset or --session (the result's data)\n");
    return kUsage;
  }
  request->session_path = session_path;
  *rig = RigOfOne(LoadDataset(dataset_path));
  (*edits)[rig->camera_names.front()] = camera_edits;
  return kOk;
}

// The report of a LiDAR-camera result, one camera's or a rig's: the data extracted and solved
// again (with the sessions' edits), each camera's pose against the result file's, the report
// written.
int ReportLidarCamera(const std::string& result_path, const std::string& session_path,
                      const std::string& dataset_path, PipelineOptions options,
                      ReportRequest request) {
  RigFolder rig;
  RigEdits edits;
  if (const int code = OpenReportedData(result_path, session_path, dataset_path, &options, &request,
                                        &rig, &edits);
      code != kOk)
    return code;
  const bool several = rig.cameras.size() > 1;
  if (several && request.check) {
    std::fprintf(stderr, "calibench report: --check goes with one camera's report, not a rig's\n");
    return kUsage;
  }
  // The poses the result reports (read first: a wrong file fails before the solve).
  const auto reported = several || IsRigResultFile(result_path)
                            ? LoadRigResult(result_path)
                            : std::vector<std::pair<std::string, Pose>>{
                                  {rig.camera_names.front(), CalibrationOf(result_path)}};
  const PipelineOptions solve =
      several ? options : KeepingInputsForViews(options, rig.cameras.front().camera, &request);
  const RigOutcome outcome = CalibrateRig(rig, solve, StderrProgress("extracted"), edits);
  if (!outcome.joint) {
    std::fprintf(stderr, "calibench report: the %s gives no calibration: %s\n",
                 several ? "rig" : "data",
                 several ? outcome.failure.c_str() : outcome.single.front().failure.c_str());
    return kNoCalibration;
  }
  // The figures are the re-solve's: say so where it is not the result's pose.
  for (const std::string& note : ResolveNotes(outcome, reported, result_path, dataset_path)) {
    request.notes.push_back(note);
    std::fprintf(stderr, "calibench report: %s\n", note.c_str());
  }
  return WriteReport(rig, outcome, options, request);
}

// `report` on a 2D LRF result: the observations extracted and solved again as `lrf-calibrate`
// does (with the session's rejections and method when given), analysed and written.
int ReportLrf(const std::string& result_path, std::string dataset_path,
              const std::string& session_path, std::string method, ReportRequest request) {
  if (request.check) {
    std::fprintf(stderr, "calibench report: --check goes with a LiDAR-camera report\n");
    return kUsage;
  }
  std::string session_file = session_path;
  if (session_file.empty() && IsLrfSession(result_path)) session_file = result_path;
  if (!IsLrfResultFile(result_path) && !IsLrfSession(result_path)) {
    std::fprintf(
        stderr, "calibench report: %s is not an LRF result (cam_from_lrf), but %s is LRF\n",
        result_path.c_str(), session_path.empty() ? dataset_path.c_str() : session_path.c_str());
    return kInputError;
  }
  if (dataset_path.empty() && session_file.empty()) {
    std::fprintf(stderr, "calibench report: give --dataset or --session (the result's data)\n");
    return kUsage;
  }
  LrfPipelineOptions options;
  if (method.empty() && session_file.empty()) method = ResultSolverMethod(result_path);
  const std::optional<LrfMethod> parsed = ParseLrfMethod(method.empty() ? "refined" : method);
  if (!parsed) {
    std::fprintf(stderr, "calibench report: --method must be refined or paper-linear, not '%s'\n",
                 method.c_str());
    return kUsage;
  }
  options.solver.method = *parsed;
  const std::unique_ptr<LrfCalibrationJob> job = OpenLrfJob(dataset_path, session_file, options);
  if (!method.empty() && job->options().solver.method != *parsed) {
    std::fprintf(stderr, "calibench report: %s solves with %s; --method %s disagrees\n",
                 session_file.c_str(), LrfMethodName(job->options().solver.method).c_str(),
                 method.c_str());
    return kUsage;
  }
  job->ExtractAll(StderrProgress("extracted"));
  const LrfCalibrationOutcome outcome = job->Solve();
  if (!outcome.solution) {
    std::fprintf(stderr, "calibench report: the data gives no calibration: %s\n",
                 outcome.failure.c_str());
    return kNoCalibration;
  }
  const std::string note = ResolveNote(
      outcome.solution->cam_from_lrf, CalibrationOf(result_path), result_path,
      "this data with these options",
      "the result, per-observation figures and scans below are the re-solve's. Pass the method "
      "lrf-calibrate was run with (or its session).");
  if (!note.empty()) {
    request.notes.push_back(note);
    std::fprintf(stderr, "calibench report: %s\n", note.c_str());
  }
  request.session_path = session_file;
  return WriteLrfReport(*job, request);
}

}  // namespace

int WriteLrfReport(const LrfCalibrationJob& job, const ReportRequest& request) {
  CALIBENCH_CHECK(job.outcome() && job.outcome()->solution);
  const std::string manifest = job.dataset().manifest.string();
  ReportProvenance provenance;
  provenance.source = request.session_path.empty()
                          ? manifest
                          : request.session_path + " (session of " + manifest + ")";
  provenance.result_file = request.result_file;
  provenance.created_utc = NowUtc();
  provenance.calibench_version = CALIBENCH_VERSION;
  provenance.notes = request.notes;
  LrfReportOptions report_options;
  report_options.cross_validate = request.options.cross_validate;
  const LrfReport report =
      AnalyseLrfCalibration(job.dataset(), *job.outcome(), job.options(), report_options);
  WriteFileAtomically(request.out_path,
                      LrfReportHtml(report, provenance, LoadReportAssets(FindAsset("report"))));
  std::printf("wrote %s (%zu observations): %s%s\n", request.out_path.c_str(), report.pairs.size(),
              report.folds ? "" : "no cross-validation: ",
              report.folds ? report.verdict.c_str() : report.cross_validation_skipped.c_str());
  if (!report.well_constrained)
    std::printf("not well constrained: the report says along which directions\n");
  return kOk;
}

int RunReport(int argc, char** argv) {
  CLI::App app{
      "Write a self-contained HTML report of a LiDAR-camera result: both directions with sigma, "
      "the method and the data's provenance, export snippets, one row per pair (residuals, "
      "weight, leave-one-out influence), held-out cross-validation with a verdict, plots, and "
      "the workbench's views. The pairs are extracted and solved again with the same pipeline. "
      "A 2D LRF result (cam_from_lrf, with its LRF dataset or session) gets the same: each "
      "observation's residual, weight, influence and held-out residual, and each scan drawn "
      "from above with the camera's target carried into it.",
      "calibench report"};
  std::string result_path, dataset_path, session_path;
  ReportRequest request;
  bool no_renders = false, no_cross_validation = false;
  app.add_option("--result,-r", result_path,
                 "calibench.result.v1 file (or a session with a result)")
      ->required();
  AddDatasetOption(app, &dataset_path, "the dataset the result was computed from");
  app.add_option("--session", session_path,
                 "the workbench session it came from (its brushes, rejections and options)");
  app.add_option("--out,-o", request.out_path, "report.html")->required();
  app.add_flag("--no-views", no_renders, "leave out the rendered views (no OpenGL needed)");
  std::string check_path;
  app.add_option("--check", check_path,
                 "a targetless check of this calibration, as `calibench check --json` printed "
                 "it: the report gains its section");
  app.add_flag("--no-cross-validation", no_cross_validation,
               "skip the leave-one-out re-solves (influence, held-out errors)");
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  request.renders = !no_renders;
  request.options.cross_validate = !no_cross_validation;
  if (!check_path.empty()) request.check = LoadTargetlessCheck(check_path);
  request.result_file = result_path;
  // The LRF method's result, dataset or session: its own report (its methods are not the
  // LiDAR-camera solver's).
  const bool result_is_session = session_path.empty() && IsSessionFile(result_path);
  if (IsLrfResultFile(result_path) ||
      JobKindOf(dataset_path, result_is_session ? result_path : session_path) == JobKind::kLrf)
    return ReportLrf(result_path, dataset_path, session_path,
                     app.count("--method") ? flags.method : "", request);
  if (!app.count("--method")) {
    const std::string method = ResultSolverMethod(result_path);
    if (!method.empty()) flags.method = method;  // the result's own method, unless overridden
  }
  std::string why;
  if (!FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench report: %s\n", why.c_str());
    return kUsage;
  }
  return ReportLidarCamera(result_path, session_path, dataset_path, flags.options, request);
}

}  // namespace calibench::app
