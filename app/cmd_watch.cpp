// `calibench watch`: follows a capture while it is written, a folder being filled or a recording
// being written, pair by pair (core/session/capture_follow.h); this file parses the flags and
// prints the events.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "app/pipeline_flags.h"
#include "core/capture/recording_watch.h"
#include "core/guidance/advise.h"
#include "core/io/camera_file.h"
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

// What `watch` is told on its command line.
struct WatchFlags {
  CaptureFollowRequest follow;
  CalibrationJobOptions options;
  bool json_lines = false;
  std::string board, camera_file;  // recordings
  WatchCheckRequest drift;         // --check: the drift meter instead
  PipelineFlags pipeline;
};

// `watch --check`: the drift meter instead of the board capture, with the recording's flags.
int WatchWithDriftMeter(const WatchFlags& w) {
  WatchCheckRequest drift = w.drift;
  drift.source = w.follow.source;
  drift.camera_file = w.camera_file;
  drift.json_lines = w.json_lines;
  drift.exit_when_sure = w.follow.exit_when_done;
  drift.idle_exit_s = w.follow.idle_exit_s;
  drift.input.cloud_topic = w.follow.import.cloud_topic;
  drift.input.image_topic = w.follow.import.image_topic;
  drift.input.camera_info_topic = w.follow.import.camera_info_topic;
  return WatchCheck(drift);
}

void AddWatchFlags(CLI::App& app, WatchFlags* w) {
  app.add_option("source", w->follow.source,
                 "the folder the capture writes (the folder form, or a folder holding a "
                 "LiDAR-camera manifest of any name; or that manifest itself), or the recording "
                 "being written (.bag, .mcap, .db3, a rosbag2 folder)")
      ->required();
  AddBoardOption(app, &w->board, "recordings: the board the camera sees");
  app.add_option("--out,-o", w->follow.out,
                 "recordings: the dataset folder the pairs are written to (default: <recording "
                 "name>.dataset beside it, as import)");
  app.add_option("--cloud-topic", w->follow.import.cloud_topic,
                 "recordings: PointCloud2 topic (default: the only one)");
  app.add_option("--image-topic", w->follow.import.image_topic,
                 "recordings: Image or CompressedImage topic (default: the only one)");
  app.add_option("--camera-info-topic", w->follow.import.camera_info_topic,
                 "recordings: CameraInfo topic (default: the one beside the image topic)");
  app.add_option("--camera", w->camera_file,
                 "recordings: intrinsics file instead of the recording's CameraInfo");
  AddGoalFlags(app, &w->options.advise);
  app.add_flag("--json-lines", w->json_lines,
               "one JSON object per line: {\"event\": \"pair\", ...} per pair, {\"event\": "
               "\"solve\", ...advise --json's fields} per solve");
  app.add_flag("--exit-when-done", w->follow.exit_when_done, "end when the stop rule says done");
  app.add_flag("--estimate-intrinsics", w->options.advise.estimate_intrinsics,
               "the camera's intrinsics are being calibrated from these pairs too: the meter "
               "includes them (done only once they are good: sigma, RMS, corners near every "
               "border) and the next pose also puts corners where the image has none (the "
               "camera file is the starting guess)");
  app.add_option("--idle-exit", w->follow.idle_exit_s,
                 "end after this many seconds without new data [s] (0 = never)")
      ->capture_default_str();
  app.add_option("--session", w->follow.session,
                 "the session file kept up to date (default: SOURCE/calibench.session.json; for a "
                 "recording, calibench.session.json in its dataset folder)");
  app.add_option("--settle", w->follow.folder.settle_s,
                 "a file is written when its size and time have not changed for this long [s]")
      ->capture_default_str();
  app.add_option("--partner-timeout", w->follow.folder.partner_timeout_s,
                 "report a cloud without its image (or the reverse) after this long [s]")
      ->capture_default_str();
  AddDriftMeterFlags(app, &w->drift);
  AddPipelineFlags(app, w->pipeline, /*with_selection=*/false);
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
  WatchFlags w;
  AddWatchFlags(app, &w);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  if (!w.drift.result.empty()) return WatchWithDriftMeter(w);
  std::string why;
  const bool pipeline_ok = FinalizePipelineFlags(w.pipeline, &why);
  w.options.advise.pipeline = w.pipeline.options;
  w.options.warm_start = true;  // each solve from the last: the capture grows by one pair
  if (!pipeline_ok || !w.follow.Check(&why) || !w.options.Check(&why)) {
    std::fprintf(stderr, "calibench watch: %s\n", why.c_str());
    return kUsage;
  }
  if (IsRecordingSource(w.follow.source)) {
    try {
      w.follow.board = BoardFromFlag(w.board);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "calibench watch: --board: %s\n", e.what());
      return kUsage;
    }
    if (!w.camera_file.empty()) w.follow.import.camera = LoadCameraFile(w.camera_file);
  }
  EventLines stream(w.json_lines);
  if (!FollowCapture(
          w.follow, w.options, [&](const FollowEvent& e) { Print(stream, e); }, &why)) {
    std::fprintf(stderr, "calibench watch: error: %s\n", why.c_str());
    return kInputError;
  }
  return kOk;
}

}  // namespace calibench::app
