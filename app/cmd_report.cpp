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
#include "core/lrf/dataset.h"
#include "core/report/lrf_report.h"
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

// What a report says when its re-solve is not the reported pose ("" when they agree to 0.1 mm
// and 0.01 deg): "<what> differs from a re-solve of <data> by .. mm and .. deg: <consequence>".
std::string ResolveNote(const Pose& solved, const Pose& reported, const std::string& what,
                        const std::string& data, const std::string& consequence) {
  const double moved_mm = 1000.0 * (solved.translation() - reported.translation()).norm();
  const double turned_deg =
      Eigen::AngleAxisd(solved.linear().transpose() * reported.linear()).angle() * kRadToDeg;
  if (moved_mm <= 0.1 && turned_deg <= 0.01) return "";
  char amount[96];
  std::snprintf(amount, sizeof(amount), " by %.1f mm and %.3f deg: ", moved_mm, turned_deg);
  return what + " differs from a re-solve of " + data + amount + consequence;
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

int WriteReport(const Dataset& dataset, const CalibrationOutcome& outcome,
                const PipelineOptions& options, const ReportRequest& request) {
  const CalibrationReport report = AnalyseCalibration(dataset, outcome, options, request.options);
  ReportProvenance provenance;
  provenance.source = request.session_path.empty() ? dataset.manifest.string()
                                                   : request.session_path + " (session of " +
                                                         dataset.manifest.string() + ")";
  provenance.result_file = request.result_file;
  provenance.created_utc = NowUtc();
  provenance.calibench_version = CALIBENCH_VERSION;
  provenance.notes = request.notes;
  std::vector<ReportFigure> figures;
  if (request.renders) {
    std::string why;
    ui::ReportFigureOptions figure_options;
    figure_options.threads = options.threads;
    figures =
        ui::DrawReportFigures(dataset, outcome, figure_options, request.kept_inputs.get(), &why);
    if (figures.empty() && !why.empty()) {
      std::fprintf(stderr, "calibench report: %s; the report has no views\n", why.c_str());
      provenance.notes.push_back("No views: " + why + ".");
    } else if (!why.empty()) {
      std::fprintf(stderr, "calibench report: %s\n", why.c_str());
      provenance.notes.push_back(why + ".");
    }
  }
  const ReportAssets assets = LoadReportAssets(FindAsset("report"));
  const std::string sections = request.check ? TargetlessCheckHtml(*request.check) : "";
  WriteFileAtomically(request.out_path, ReportHtml(report, provenance, figures, assets, sections));
  std::printf("wrote %s (%zu pairs, %zu views)%s%s\n", request.out_path.c_str(),
              report.pairs.size(), figures.size(), report.cross_validation ? ": " : "",
              report.cross_validation ? report.cross_validation->verdict.c_str() : "");
  if (!report.distrust.empty()) std::printf("%s\n", report.distrust.c_str());
  return kOk;
}

int WriteRigReport(const RigFolder& rig, const RigOutcome& outcome, const PipelineOptions& options,
                   const ReportRequest& request) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  const RigReportSummary summary = SummarizeRigOutcome(outcome);
  std::vector<RigCameraReport> cameras;
  std::string why;
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const std::string& name = outcome.camera_names[c];
    RigCameraReport camera;
    camera.name = name;
    camera.prefix = "camera" + std::to_string(c) + "-";  // ids stay valid whatever the name
    camera.report = AnalyseCalibration(rig.cameras[c], outcome.single[c], options, request.options);
    if (request.renders && why.empty()) {
      ui::ReportFigureOptions figure_options;
      figure_options.threads = options.threads;
      camera.figures = ui::DrawRigReportFigures(rig, outcome, c, figure_options, &why);
    }
    cameras.push_back(std::move(camera));
  }
  ReportProvenance provenance;
  provenance.source = rig.folder.string() + " (a rig of " +
                      std::to_string(outcome.camera_names.size()) + " cameras)";
  provenance.result_file = request.result_file;
  provenance.created_utc = NowUtc();
  provenance.calibench_version = CALIBENCH_VERSION;
  provenance.notes = request.notes;
  if (!why.empty()) {
    std::fprintf(stderr, "calibench report: %s; the report has no views\n", why.c_str());
    provenance.notes.push_back("No views: " + why + ".");
  }
  const ReportAssets assets = LoadReportAssets(FindAsset("report"));
  WriteFileAtomically(request.out_path, RigReportHtml(summary, cameras, provenance, assets));
  std::printf("wrote %s (a rig of %zu cameras", request.out_path.c_str(), cameras.size());
  for (const RigCameraReport& camera : cameras)
    std::printf(
        "; %s: %zu pairs, %zu views%s%s", camera.name.c_str(), camera.report.pairs.size(),
        camera.figures.size(), camera.report.cross_validation ? ", " : "",
        camera.report.cross_validation ? camera.report.cross_validation->verdict.c_str() : "");
  std::printf(")\n");
  return kOk;
}

namespace {

// `report` on a rig: the rig solved again (with the sessions' edits), each camera's pose against
// the result file's, the report written.
int ReportRig(const std::string& result_path, const std::string& dataset_path,
              const RigEdits& edits, const PipelineOptions& options, ReportRequest request) {
  if (request.check) {
    std::fprintf(stderr, "calibench report: --check goes with one camera's report, not a rig's\n");
    return kUsage;
  }
  const RigFolder rig = LoadRig(dataset_path);
  const RigOutcome outcome = CalibrateRig(rig, options, StderrProgress("extracted"), edits);
  if (!outcome.joint) {
    std::fprintf(stderr, "calibench report: the rig gives no calibration: %s\n",
                 outcome.failure.c_str());
    return kNoCalibration;
  }
  for (const auto& [name, reported] : LoadRigResult(result_path)) {
    const auto at = std::find(outcome.camera_names.begin(), outcome.camera_names.end(), name);
    if (at == outcome.camera_names.end()) {
      request.notes.push_back(result_path + " has a camera '" + name + "' that " + dataset_path +
                              " has not.");
      continue;
    }
    const std::string note =
        ResolveNote(outcome.joint->cam_from_lidar[at - outcome.camera_names.begin()], reported,
                    result_path + ": camera " + name, "this rig with these options",
                    "the figures below are the re-solve's.");
    if (note.empty()) continue;
    request.notes.push_back(note);
    std::fprintf(stderr, "calibench report: %s\n", note.c_str());
  }
  return WriteRigReport(rig, outcome, options, request);
}

// The report of one camera's dataset: the pairs extracted and solved again (with the session's
// edits, when there is one) and reported.
int ReportDataset(const std::string& result_path, std::string session_path,
                  std::string dataset_path, PipelineOptions options, ReportRequest request) {
  if (session_path.empty() && IsSessionFile(result_path)) session_path = result_path;
  const Pose reported = CalibrationOf(result_path);
  const PairEdits edits = ApplySessionFlag(session_path, &dataset_path, &options);
  if (dataset_path.empty()) {
    std::fprintf(stderr, "calibench report: give --dataset or --session (the result's data)\n");
    return kUsage;
  }
  request.session_path = session_path;
  const Dataset dataset = LoadDataset(dataset_path);
  const CalibrationOutcome outcome =
      CalibrateDataset(dataset, KeepingInputsForViews(options, dataset.camera, &request),
                       StderrProgress("extracted"), edits);
  if (!outcome.solution) {
    std::fprintf(stderr, "calibench report: the data gives no calibration: %s\n",
                 outcome.failure.c_str());
    return kNoCalibration;
  }
  // The figures are the re-solve's: say so when it is not the result's pose.
  const std::string note = ResolveNote(
      outcome.solution->cam_from_lidar, reported, result_path, "this data with these options",
      "the result, per-pair figures and views below are the re-solve's. Pass the options "
      "calibrate was run with (or its session).");
  if (!note.empty()) {
    request.notes.push_back(note);
    std::fprintf(stderr, "calibench report: %s\n", note.c_str());
  }
  return WriteReport(dataset, outcome, options, request);
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
  if (IsRigResultFile(result_path) || (!dataset_path.empty() && IsRig(dataset_path))) {
    if (dataset_path.empty()) {
      std::fprintf(stderr, "calibench report: a rig result: give --dataset <the rig>\n");
      return kUsage;
    }
    RigEdits edits;
    if (!session_path.empty()) {
      const Session session = LoadSession(session_path);
      edits[session.camera] = EditsFromSession(session);
    }
    return ReportRig(result_path, dataset_path, edits, flags.options, request);
  }
  return ReportDataset(result_path, session_path, dataset_path, flags.options, request);
}

}  // namespace calibench::app
