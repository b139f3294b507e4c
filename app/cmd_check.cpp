// `calibench check`: is a calibration still right, judged from the scene without a target
// (core/targetless).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "app/pipeline_flags.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/io/dataset_source.h"
#include "core/io/image_io.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "core/targetless/check_input.h"
#include "core/targetless/check_output.h"
#include "core/targetless/check_overlay.h"
#include "core/targetless/checked_calibration.h"

namespace calibench::app {

namespace {

struct CheckFlags {
  std::string dataset, result, guess, camera_frame, write_result, camera, views;
  int max_views = 6;
  bool json = false;
  CheckOptions check;
  CheckInputOptions input;
};

void AddCheckFlags(CLI::App& app, CheckFlags& f) {
  AddDatasetOption(app, &f.dataset,
                   "the scene: a dataset folder or manifest, or a recording (any board in it is "
                   "not used)")
      ->required();
  app.add_option("--result,-r", f.result,
                 "the calibration to check: a calibench.result.v1 file, a session with a "
                 "result, or any export (URDF, TF, Autoware, OpenCV YAML, Kalibr, txt)");
  app.add_option("--guess", f.guess,
                 "a rough guess instead of a calibration: 'x y z roll pitch yaw' (the camera in "
                 "the LiDAR frame as a URDF joint's origin gives it: metres, degrees), or a file "
                 "as --result takes; refined and reported (verdict 'refined'), never judged "
                 "miscalibrated. Widen --search-deg / --search-m to how far off it may be");
  app.add_option("--camera-frame", f.camera_frame,
                 "the camera frame of --guess's numbers and of an exported file: link (x forward, "
                 "REP 103) or optical (z forward). Default: link for typed numbers, optical for "
                 "files (as `calibench export` writes them)");
  app.add_flag("--json", f.json, "print exactly one JSON object on stdout");
  app.add_option("--search-deg", f.check.alignment.search_deg,
                 "how far the rotation may be off the calibration [deg] (3 for a CAD mount)")
      ->capture_default_str();
  app.add_option("--search-m", f.check.alignment.search_m,
                 "how far the translation may be off the calibration [m] (0.2 for a CAD mount)")
      ->capture_default_str();
  app.add_option("--tolerance-deg", f.check.tolerance_deg,
                 "the smallest rotation change called a miscalibration [deg]")
      ->capture_default_str();
  app.add_option("--tolerance-m", f.check.tolerance_m,
                 "the smallest translation change called a miscalibration [m]")
      ->capture_default_str();
  app.add_option("--write-result", f.write_result,
                 "save the targetless estimate as a calibench.result.v1 file whose provenance "
                 "says targetless");
  app.add_option("--views", f.views,
                 "draw frames into this folder: the LiDAR's edges on the image under the "
                 "calibration (red) and under the estimate (green), check_<frame>.png");
  app.add_option("--max-views", f.max_views, "with --views: at most this many frames")
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--edges",
         [&f](const std::string& kinds) {
           f.check.lidar_edges.depth_edges = kinds.find("depth") != std::string::npos;
           f.check.lidar_edges.intensity_edges = kinds.find("intensity") != std::string::npos;
         },
         "which LiDAR edges to align: depth, intensity or depth,intensity")
      ->default_str("depth,intensity");
  app.add_option("--camera", f.camera,
                 "camera intrinsics file, instead of the dataset's camera.yaml or the "
                 "recording's CameraInfo");
  app.add_option("--max-frames", f.input.max_frames,
                 "recordings: at most this many frames, spread over the recording")
      ->capture_default_str();
  app.add_option("--frame-interval", f.input.frame_interval_s,
                 "recordings: at most one frame per this many seconds")
      ->capture_default_str();
  app.add_option("--cloud-topic", f.input.cloud_topic, "recordings: the PointCloud2 topic");
  app.add_option("--image-topic", f.input.image_topic, "recordings: the image topic");
  app.add_option("--threads", f.input.threads, "worker threads (0 = all cores)")
      ->capture_default_str();
}

// --views: each drawn frame's image read again (the check keeps only edges).
void DrawViews(const CheckFlags& f, const CheckInput& input, const CheckReport& report) {
  std::string why;
  const std::optional<DatasetSource> source = RecogniseDataset(f.dataset, &why);
  if (!source || source->kind != DatasetKind::kLidarCamera) {
    std::fprintf(stderr, "calibench check: --views draws dataset frames only (not a recording)\n");
    return;
  }
  const Dataset dataset = LoadDataset(f.dataset, CameraFile::kOptional, TargetFile::kOptional);
  std::filesystem::create_directories(f.views);
  int drawn = 0;
  for (const EdgeFrame& frame : input.frames) {
    if (drawn >= f.max_views) break;
    for (const PairEntry& pair : dataset.pairs) {
      if (pair.id != frame.id) continue;
      std::vector<OverlayPose> poses = {{report.reference, 40, 40, 255}};
      if (report.has_estimate) poses.push_back({report.estimate, 60, 255, 60});
      const std::filesystem::path path =
          std::filesystem::path(f.views) / ("check_" + frame.id + ".png");
      SaveImage(path,
                DrawEdgeOverlay(LoadImage(pair.image), frame.lidar_edges, input.camera, poses));
      ++drawn;
    }
  }
  std::fprintf(stderr, "calibench check: drew %d frames into %s\n", drawn, f.views.c_str());
}

// The pose checked (--result) or refined (--guess, which sets f->check.reference_is_guess);
// nullopt after saying what is wrong with the flags. A file that cannot be read throws IoError.
std::optional<CheckedCalibration> ReadCheckedPose(CheckFlags* flags) {
  const CheckFlags& f = *flags;
  if (f.result.empty() == f.guess.empty()) {
    std::fprintf(stderr,
                 "calibench check: give the calibration to check (--result) or a rough "
                 "guess to refine (--guess), one of them\n");
    return std::nullopt;
  }
  std::optional<CameraFrame> camera_frame;
  if (!f.camera_frame.empty() && !(camera_frame = ParseCameraFrame(f.camera_frame))) {
    std::fprintf(stderr, "calibench check: --camera-frame must be link or optical, got '%s'\n",
                 f.camera_frame.c_str());
    return std::nullopt;
  }
  CheckedCalibration checked;
  const std::string source = f.result.empty() ? f.guess : f.result;
  if (!f.guess.empty() && !std::filesystem::exists(f.guess)) {
    try {
      checked = GuessFromJointOrigin(f.guess, camera_frame.value_or(CameraFrame::kLink));
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "calibench check: --guess: %s (or no such file)\n", e.what());
      return std::nullopt;
    }
  } else {
    ExportFrames frames;
    frames.camera_frame = camera_frame.value_or(CameraFrame::kOptical);
    checked = LoadCheckedCalibration(source, frames);
  }
  // A guess has no covariance to weigh a change against: it is refined, never judged.
  flags->check.reference_is_guess = !f.guess.empty();
  if (f.check.reference_is_guess) checked.camera_axes_covariance.setZero();
  std::fprintf(stderr, "calibench check: %s: %s\n", f.guess.empty() ? "checking" : "refining",
               checked.how.c_str());
  return checked;
}

}  // namespace

int RunCheck(int argc, char** argv) {
  CLI::App app{
      "Judge a calibration without a target: the scene's edges (depth jumps and paint the LiDAR "
      "sees, edges in the image) are aligned around it. Says consistent, miscalibrated (with "
      "a targetless estimate and its sigma) or cannot tell, naming the axes the scene cannot "
      "constrain. Exit 0 for every verdict.",
      "calibench check"};
  CheckFlags f;
  AddCheckFlags(app, f);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  f.check.alignment.threads = f.input.threads;
  if (!f.camera.empty()) f.input.camera = LoadCameraFile(f.camera);
  std::string why;
  if (!f.check.Check(&why) || !f.input.Check(&why)) {
    std::fprintf(stderr, "calibench check: %s\n", why.c_str());
    return kUsage;
  }
  const std::optional<CheckedCalibration> checked = ReadCheckedPose(&f);
  if (!checked) return kUsage;
  MachineStdout out(f.json);  // from here on, only the JSON object reaches stdout
  const Pose& reference = checked->cam_from_lidar;
  const Mat6& reference_covariance = checked->camera_axes_covariance;
  const ProgressCallback progress = StderrProgress("read");
  const CheckInput input =
      LoadCheckInput(f.dataset, f.check, f.input, [&](int done, int total, const std::string& id) {
        // A recording's frame count is known only at its end.
        if (total > 0)
          progress(done, total, id);
        else
          std::fprintf(stderr, "[%d] read frame %s\n", done, id.c_str());
      });
  for (const std::string& problem : input.unreadable)
    std::fprintf(stderr, "calibench check: skipped %s\n", problem.c_str());
  const CheckReport report =
      CheckCalibration(input.frames, input.camera, reference, reference_covariance, f.check);
  if (f.json)
    out.Print(CheckReportJson(report));
  else
    std::printf("%s", FormatCheckReport(report).c_str());
  if (!f.views.empty()) DrawViews(f, input, report);
  if (!f.write_result.empty()) {
    if (!report.has_estimate) {
      std::fprintf(stderr,
                   "calibench check: --write-result: no targetless estimate to write (%s)\n",
                   report.why.c_str());
      return kNoCalibration;
    }
    WriteCheckResult(f.write_result, report, f.result.empty() ? checked->how : f.result);
    std::fprintf(stderr, "calibench check: wrote the targetless estimate to %s\n",
                 f.write_result.c_str());
  }
  return kOk;
}

}  // namespace calibench::app
