// `calibench watch`: follows a capture while it is written (a folder in the folder form that a
// capture script fills, or a recording that rosbag / ros2 bag / an MCAP logger is writing), pair
// by pair: detect, pre-flight, accept or reject, solve again, σ against the goal, the next pose
// (core/session/capture_follow.h; this file parses the flags and prints the events).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "app/pipeline_flags.h"
#include "core/guidance/stop_rule.h"
#include "core/io/camera_file.h"
#include "core/io/recording_watch.h"
#include "core/session/capture_follow.h"

namespace calibench::app {
namespace {
// A follower's event as a JSON line or words.
void Print(EventLines& stream, const FollowEvent& e) {
  if (e.event == "solve") {
    nlohmann::json solve = nlohmann::json::parse(CaptureAdviceJson(*e.advice));
    solve["event"] = "solve";
    solve["latency_s"] = e.latency_s;
    return stream.Emit(solve.dump(), DescribeCaptureProgress(*e.advice));
  }
  if (e.event == "pair")
    return stream.Emit(
        nlohmann::json{
            {"event", "pair"}, {"name", e.name}, {"accepted", e.accepted}, {"reason", e.reason}}
            .dump(),
        e.name + ": " + (e.accepted ? "accepted" : PairStatusName(e.status) + ": " + e.reason));
  stream.Emit(nlohmann::json{{"event", e.event}, {"name", e.name}, {"reason", e.reason}}.dump(),
              e.event + (e.name.empty() ? "" : " " + e.name) + ": " + e.reason);
}

// `watch --check`: the drift meter instead of the board capture, with the recording's flags.
int WatchWithDriftMeter(WatchCheckRequest drift, const CaptureFollowRequest& request,
                        bool json_lines, const std::string& camera_file) {
  drift.source = request.source;
  drift.camera_file = camera_file;
  drift.json_lines = json_lines;
  drift.exit_when_sure = request.exit_when_done;
  drift.idle_exit_s = request.idle_exit_s;
  drift.input.cloud_topic = request.import.cloud_topic;
  drift.input.image_topic = request.import.image_topic;
  drift.input.camera_info_topic = request.import.camera_info_topic;
  return WatchCheck(drift);
}

}  // namespace

int RunWatch(int argc, char** argv) {
  CLI::App app{
      "Follow a capture while it is written: a folder in the folder form (clouds/, images/, "
      "camera.yaml, target.json) that grows pair by pair, or a recording being written (ROS 1 "
      ".bag, .mcap, rosbag2 .db3 or its folder), whose pairs are chosen as `import` chooses "
      "them and written to a dataset folder. Each new pair is detected, checked, accepted or "
      "rejected with the reason, and everything so far is solved again: σ against the goal and "
      "where to hold the board next, per pair.",
      "calibench watch"};
  CaptureFollowRequest flags;
  bool json_lines = false;
  CalibrationJobOptions options;
  app.add_option("source", flags.source,
                 "the folder the capture writes (the folder form, or a folder holding a "
                 "LiDAR-camera manifest of any name; or that manifest itself), or the recording "
                 "being written (.bag, .mcap, .db3, a rosbag2 folder)")
      ->required();
  std::string board, out, camera_file;
  AddBoardOption(app, &board, "recordings: the board the camera sees");
  app.add_option("--out,-o", out,
                 "recordings: the dataset folder the pairs are written to (default: <recording "
                 "name>.dataset beside it, as import)");
  app.add_option("--cloud-topic", flags.import.cloud_topic,
                 "recordings: PointCloud2 topic (default: the only one)");
  app.add_option("--image-topic", flags.import.image_topic,
                 "recordings: Image or CompressedImage topic (default: the only one)");
  app.add_option("--camera-info-topic", flags.import.camera_info_topic,
                 "recordings: CameraInfo topic (default: the one beside the image topic)");
  app.add_option("--camera", camera_file,
                 "recordings: intrinsics file instead of the recording's CameraInfo");
  app.add_option("--goal-mm", options.advise.goal.translation_mm,
                 "goal: 1σ of the translation per axis [mm]")
      ->capture_default_str();
  app.add_option("--goal-deg", options.advise.goal.rotation_deg,
                 "goal: 1σ of the rotation per axis [deg]")
      ->capture_default_str();
  app.add_flag("--json-lines", json_lines,
               "one JSON object per line: {\"event\": \"pair\", ...} per pair, {\"event\": "
               "\"solve\", ...advise --json's fields} per solve");
  app.add_flag("--exit-when-done", flags.exit_when_done, "end when the stop rule says done");
  app.add_flag("--estimate-intrinsics", options.advise.estimate_intrinsics,
               "the camera's intrinsics are being calibrated from these pairs too: the meter "
               "includes them (done only once they are good: sigma, RMS, corners near every "
               "border) and the next pose also puts corners where the image has none (the "
               "camera file is the starting guess)");
  app.add_option("--idle-exit", flags.idle_exit_s,
                 "end after this many seconds without new data [s] (0 = never)")
      ->capture_default_str();
  app.add_option("--session", flags.session,
                 "the session file kept up to date (default: SOURCE/calibench.session.json; for a "
                 "recording, calibench.session.json in its dataset folder)");
  app.add_option("--settle", flags.folder.settle_s,
                 "a file is written when its size and time have not changed for this long [s]")
      ->capture_default_str();
  app.add_option("--partner-timeout", flags.folder.partner_timeout_s,
                 "report a cloud without its image (or the reverse) after this long [s]")
      ->capture_default_str();
  WatchCheckRequest drift;
  AddDriftMeterFlags(app, &drift);
  PipelineFlags pipeline;
  AddPipelineFlags(app, pipeline, /*with_selection=*/false);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  if (!drift.result.empty()) return WatchWithDriftMeter(drift, flags, json_lines, camera_file);
  std::string why;
  if (!FinalizePipelineFlags(pipeline, &why) || !flags.Check(&why)) {
    std::fprintf(stderr, "calibench watch: %s\n", why.c_str());
    return kUsage;
  }
  options.advise.pipeline = pipeline.options;
  options.warm_start = true;  // each solve from the last: the capture grows by one pair
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench watch: %s\n", why.c_str());
    return kUsage;
  }
  if (IsRecordingSource(flags.source)) {
    try {
      flags.board = BoardFromFlag(board);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "calibench watch: --board: %s\n", e.what());
      return kUsage;
    }
    if (!camera_file.empty()) flags.import.camera = LoadCameraFile(camera_file);
    flags.out = out;
  }
  EventLines stream(json_lines);
  if (!FollowCapture(
          flags, options, [&](const FollowEvent& e) { Print(stream, e); }, &why)) {
    std::fprintf(stderr, "calibench watch: error: %s\n", why.c_str());
    return kInputError;
  }
  return kOk;
}

}  // namespace calibench::app
