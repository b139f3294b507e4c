// Subcommands of the calibench executable. Each parses its own flags into core Options and
// returns the process exit code (see ExitCode).
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/board/board.h"
#include "core/intrinsics/intrinsics.h"
#include "core/report/report_html.h"
#include "core/report/targetless_section.h"
#include "core/session/session.h"
#include "core/targetless/check_follow.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace calibench {
struct RigFolder;         // core/io/rig_folder.h
struct RigOutcome;        // core/lidar_camera/rig.h
class LrfCalibrationJob;  // core/session/lrf_calibration_job.h
}  // namespace calibench

namespace calibench::ui {
class KeptPairInputs;  // ui/lidar_camera/report_figures.h
}  // namespace calibench::ui

namespace calibench::app {

// Exit codes shared by every subcommand.
enum ExitCode : int {
  kOk = 0,
  kUsage = 1,           // bad flags or options
  kInputError = 2,      // a file is missing, unreadable or malformed
  kNoCalibration = 3,   // too few usable pairs, no initial guess
  kNotConstrained = 4,  // a result was written but the planes do not fix all six dof
  kAccuracyFailed = 5,  // evaluate: error above the given bounds
};

// Parses a subcommand's flags; the exit code when parsing ends the command (--help printed: kOk;
// a bad flag, reported: kUsage), nullopt when the command goes on.
// A mistyped flag gets a suggestion ("did you mean --threads?").
std::optional<int> ParseFlags(CLI::App& app, int argc, char** argv);
// The candidate nearest to `word` by edit distance, or "" when none is near (a third of its
// length, at least 2 edits).
std::string Closest(const std::string& word, const std::vector<std::string>& candidates);

// Prints a table (Markdown) on stdout and, when `path` is not empty, writes it there atomically;
// kOk, or kInputError with the file and the reason on stderr (prefixed by `command`).
int PrintAndWriteTable(const std::string& table, const std::string& path, const char* command);

// --dataset,-d of every command that opens a dataset: `what` names the kind it needs; the help
// adds how a path is recognised (core/io/dataset_source.h: a manifest of any name, a folder).
CLI::Option* AddDatasetOption(CLI::App& app, std::string* path, const std::string& what);
// --board of `import` and `gui` (BoardFromFlag): `what` says which board it is.
CLI::Option* AddBoardOption(CLI::App& app, std::string* board, const std::string& what);

int RunCalibrate(int argc, char** argv);
int RunAdvise(int argc, char** argv);
int RunWatch(int argc, char** argv);
// `check`: a calibration judged without a target (core/targetless).
int RunCheck(int argc, char** argv);
int RunCheckSweep(int argc, char** argv);
// `watch --check R RECORDING`: the drift meter (app/cmd_watch_check.cpp).
struct WatchCheckRequest {
  std::string source, result;
  std::string camera_file;  // intrinsics instead of the recording's CameraInfo ("" = those)
  CheckOptions check;
  CheckInputOptions input;
  DriftMeterOptions drift;
  bool json_lines = false;
  bool exit_when_sure = false;
  double idle_exit_s = 0.0;
};
// --check and --check-every of `watch`.
void AddDriftMeterFlags(CLI::App& app, WatchCheckRequest* request);
// Checks the request's options (kUsage with the reason on stderr), then follows the recording.
int WatchCheck(WatchCheckRequest request);
int RunEvaluate(int argc, char** argv);
// `evaluate --subsets`: the σ-honesty protocol (core/evaluation/subset_coverage.h).
int RunEvaluateSubsets(int argc, char** argv);
int RunSimulate(int argc, char** argv);
int RunDemo(int argc, char** argv);
int RunSweep(int argc, char** argv);
// `sweep --guided`: guided against random placement (core/evaluation/guided_sweep.h).
int RunSweepGuided(int argc, char** argv);
int RunLrfCalibrate(int argc, char** argv);
// `simulate --kind lrf` and the LRF side of `evaluate` (dispatched from RunSimulate/RunEvaluate).
int RunSimulateLrf(int argc, char** argv);
int RunEvaluateLrf(int argc, char** argv);
int RunSweepLrf(int argc, char** argv);
// True when the file is a calibench.lrf-dataset.v1 manifest.
bool IsLrfManifest(const std::string& path);
int RunGui(int argc, char** argv);
int RunRender(int argc, char** argv);
int RunExport(int argc, char** argv);
// cam_from_lidar (or cam_from_lrf) of a calibench.result.v1 file or of a session's last solve
// (`export`, `report`). Throws IoError naming the file, also for a session without a result.
Pose CalibrationOf(const std::filesystem::path& path);
int RunTarget(int argc, char** argv);
int RunIntrinsics(int argc, char** argv);
// `intrinsics` and `calibrate --estimate-intrinsics`: the board detected in each image, then
// CalibrateIntrinsics; the images without a board are listed as not used. Throws
// std::invalid_argument when too few images show the board, IoError for unreadable files.
// "pinhole" -> pinhole-radtan, "fisheye" -> kannala-brandt (--model of `intrinsics`,
// --intrinsics-model of `calibrate`); nullopt for other names.
std::optional<CameraModelType> ParseIntrinsicsModel(const std::string& name);
// --estimate-intrinsics of `calibrate` and `advise`: the pairs' images calibrate the camera
// (model pinhole | fisheye) into dataset->camera, said on `out`; an exit code (kOk or why not).
int EstimateDatasetIntrinsics(const char* command, const std::string& model, Dataset* dataset,
                              std::optional<IntrinsicsResult>* result, std::FILE* out = stdout);
IntrinsicsResult EstimateIntrinsicsFromImages(const std::vector<IntrinsicsImageFile>& files,
                                              const BoardSpec& board,
                                              const IntrinsicsOptions& options);
int RunImport(int argc, char** argv);
// --board of `import` and `gui`: a preset's name or a target.json file; empty = nullopt (the
// target.json beside the recording, else the preset that fits its images). Throws
// std::invalid_argument naming the presets for an unknown name, IoError for a bad file.
std::optional<BoardSpec> BoardFromFlag(const std::string& board);

// How `gui` runs its window. A test's window closes by itself (0 = never) after that many frames
// drawn back to back, or after that many seconds of a normal run.
struct GuiWindowFlags {
  int after_frames = 0;
  double after_seconds = 0.0;
  bool fresh = false;  // --fresh: back up the session beside the dataset and start a new one
  std::string bag;     // --bag: a recording to import and open
  std::string board;   // --board: the board in imported recordings (preset or target.json; empty =
                       // automatic)
  std::vector<std::string> test_drops;  // --test-drop: paths dropped onto the window (tests)
  std::string watch;                    // --watch: a folder a capture fills, followed live
  std::string frame_log;                // --frame-log: per-frame times to this file
  double screenshot_every_s = 0.0;      // --screenshot-every: also <screenshot stem>_<n>.png
  bool no_auto_solve = false;           // --no-auto-solve: solve only on F5 / Run
  std::string camera;                   // --camera: the rig camera to open (default: the first)
};
// Shared by `gui` and `demo`: opens the workbench window on a dataset or session.
int RunGuiWindow(const std::string& dataset, const std::string& session, int width, int height,
                 const std::string& screenshot, const GuiWindowFlags& quit = {});
// Shared by `render` and `demo`: draws one view (or the workbench) headless into a PNG; with
// save_session, writes the session there (a failure is an error); with intrinsics, the
// camera-intrinsics window open over it, estimated from the loaded pairs.
int RenderHeadless(const std::string& dataset, const std::string& session, const std::string& pair,
                   bool solve, const std::string& view, int width, int height,
                   const std::string& out, const std::string& backend_name,
                   const std::string& save_session, bool intrinsics = false,
                   const std::string& camera = "");
// `demo` on a machine without a display: solve and write the workbench and each view as PNG.
int RenderDemoViews(const std::string& dataset, const std::string& out_dir);
int RunReport(int argc, char** argv);
// What a report is written from, besides the pipeline's outcome.
struct ReportRequest {
  std::string out_path;
  std::string session_path;  // the workbench session, when the data came from one
  std::string result_file;   // the result reported on ("" when written with the solve)
  bool renders = true;       // draw the views headless
  ReportOptions options;
  std::vector<std::string> notes;  // shown at the top
  // `check --json`'s output, read when the flags are (a wrong file fails before the solve): the
  // targetless-check section (none when absent).
  std::optional<TargetlessCheckSection> check;
  // The pairs' files as the extraction read them (PipelineOptions::on_pair_inputs), for the views;
  // null: the views read them again.
  std::shared_ptr<ui::KeptPairInputs> kept_inputs;
};
// `report` and `calibrate --report` on a LiDAR-camera solve, one camera's (a rig of one: RigOfOne,
// RigOutcomeOfOne) or a rig's: analyses each camera's outcome, draws the views, writes the HTML
// atomically (a rig's with the rig solve first, core/report/report_html.h RigReportHtml); kOk (an
// unreadable asset throws IoError). Needs outcome.joint; request.check only for one camera.
int WriteReport(const RigFolder& rig, const RigOutcome& outcome, const PipelineOptions& options,
                const ReportRequest& request);
// `report` and `calibrate --report` on a 2D LRF job that has solved: analyses its outcome (the
// leave-one-out folds) and writes the HTML atomically; kOk.
int WriteLrfReport(const LrfCalibrationJob& job, const ReportRequest& request);
// `options` set to keep each pair's files for the report's views as the extraction reads them
// (request->kept_inputs; PipelineOptions::on_pair_inputs), when the report is written with views;
// unchanged otherwise. The returned options refer to request->kept_inputs.
PipelineOptions KeepingInputsForViews(const PipelineOptions& options, const CameraModel& camera,
                                      ReportRequest* request);

}  // namespace calibench::app
