// `calibench watch`: follows a capture while it is written (a folder in the folder form that a
// capture script fills, or a recording that rosbag / ros2 bag / an MCAP logger is writing), pair
// by pair: detect, pre-flight, accept or reject, solve again, σ against the goal, the next pose
// (core/session/calibration_job.h over core/io/capture_feed.h: a folder or a recording).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "app/pipeline_flags.h"
#include "core/guidance/stop_rule.h"
#include "core/io/camera_file.h"
#include "core/io/capture_feed.h"
#include "core/io/dataset_source.h"
#include "core/io/recording_watch.h"
#include "core/session/calibration_job.h"
#include "core/session/feature_cache.h"
#include "core/session/session.h"

namespace calibench::app {
namespace {
namespace fs = std::filesystem;

double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double UnixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Where the stream goes: one JSON object per line, or one line for people per event.
class EventStream {
 public:
  explicit EventStream(bool json_lines) : json_lines_(json_lines), out_(json_lines) {}

  void Emit(nlohmann::json event, const std::string& human) {
    if (json_lines_) {
      event["time"] = UnixSeconds();
      out_.Print(event.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    } else {
      out_.Print(human);
    }
  }
  void Note(const std::string& kind, const std::string& name, const std::string& reason) {
    Emit({{"event", kind}, {"name", name}, {"reason", reason}},
         kind + (name.empty() ? "" : " " + name) + ": " + reason);
  }

 private:
  bool json_lines_;
  MachineStdout out_;  // with --json-lines, only the events reach stdout
};

// The advice's first line (σ against the goal) and the next pose in words.
std::string HumanProgress(const CaptureAdvice& advice) {
  std::string line;
  if (advice.state) {
    line = DescribeCaptureState(*advice.state, advice.goal);
  } else {
    line = std::to_string(advice.pairs_used) + " pairs accepted: no calibration yet";
  }
  if (advice.next) line += "; next: " + advice.next->words;
  return line;
}

struct WatchFlags {
  std::string source;
  fs::path manifest;  // a manifest given instead of its folder
  fs::path out;       // recordings: the dataset folder the pairs are written to
  std::optional<BoardSpec> board;
  BagImportOptions import;
  std::string session;
  bool json_lines = false;
  bool exit_when_done = false;
  double idle_exit_s = 0.0;
  double poll_s = 0.1;
  FolderWatchOptions folder;
};

// The capture's camera and target: the folder form's camera.yaml and target.json, or a
// LiDAR-camera manifest of any name in the folder (core/io/dataset_source.h; its pairs are the
// files clouds/ and images/ hold as they come). A capture script may write them after starting:
// waits, and when --idle-exit passes first, returns nullopt with the resolver's *why (what was
// looked for). Another kind of dataset is refused at once (IoError naming the command for it).
std::optional<Dataset> WaitForSetup(const WatchFlags& flags, EventStream& stream,
                                    std::string* why) {
  const fs::path folder = fs::absolute(flags.source);
  const double start = SteadySeconds();
  bool said = false;
  for (;;) {
    std::error_code error;
    if (flags.manifest.empty() && fs::exists(folder / "camera.yaml", error) &&
        fs::exists(folder / "target.json", error))
      return LoadFolderSetup(folder);
    const std::optional<DatasetSource> source =
        flags.manifest.empty() ? RecogniseDataset(folder, why) : std::nullopt;
    if (!flags.manifest.empty() || (source && !source->folder_form)) {
      const DatasetSource lidar_camera = ResolveDataset(
          flags.manifest.empty() ? folder : flags.manifest, DatasetKind::kLidarCamera);
      Dataset setup = LoadDataset(lidar_camera.path);
      setup.pairs.clear();
      setup.manifest = folder;
      return setup;
    }
    if (!said) {
      stream.Note(
          "waiting", "",
          "waiting for camera.yaml and target.json (or a dataset manifest) in " + folder.string());
      said = true;
    }
    if (flags.idle_exit_s > 0 && SteadySeconds() - start >= flags.idle_exit_s) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::duration<double>(flags.poll_s));
  }
}

// The features a watch detected, kept beside its session (core/session/feature_cache.h): what an
// earlier watch of the capture left is reused, and each pair is appended when it is new or the
// solve changed it.
class FeatureCacheKeeper {
 public:
  explicit FeatureCacheKeeper(const fs::path& session_path)
      : path_(FeatureCachePath(session_path)),
        earlier_(LoadFeatureCache(path_, &skipped_)),
        writer_(path_) {}

  // The earlier features of `pair`, when its files are the same; counted for ResumedNote.
  const PairFeatures* Earlier(const PairEntry& pair) {
    const auto hit = earlier_.find(pair.id);
    if (hit == earlier_.end() || hit->second.entry.cloud != pair.cloud ||
        hit->second.entry.image != pair.image)
      return nullptr;
    written_[pair.id] = StateOf(hit->second.features);
    ++resumed_;
    return &hit->second.features;
  }
  // "N pairs taken from ..." once per batch that reused any; "" otherwise.
  std::string ResumedNote() {
    if (resumed_ == 0) return "";
    std::string note =
        std::to_string(resumed_) + " pairs taken from " + path_.string() + ", not detected again";
    if (skipped_ > 0)
      note += " (" + std::to_string(skipped_) + " stale or cut-short lines ignored)";
    resumed_ = 0;
    return note;
  }
  // Appends the job's pairs that are new or changed since written; the failures, in words.
  std::vector<std::string> Record(const CalibrationJob& job) {
    std::vector<std::string> failures;
    const std::vector<PairFeatures> detected = job.DetectedPairs();
    for (size_t i = 0; i < detected.size(); ++i) {
      const PairFeatures& features = detected[i];
      std::string& written = written_[features.id];
      if (written == StateOf(features)) continue;
      try {
        writer_.Append(job.dataset().pairs[i], features);
        written = StateOf(features);
      } catch (const IoError& e) {
        failures.push_back(features.id + ": feature cache: " + e.what());
      }
    }
    return failures;
  }

 private:
  // What distinguishes two versions of a pair's features in the cache.
  static std::string StateOf(const PairFeatures& f) {
    return PairStatusName(f.status) + (f.lidar ? "+lidar" : "") + (f.camera ? "+camera" : "") +
           ":" + f.reason;
  }

  fs::path path_;
  int skipped_ = 0;
  std::map<std::string, CachedPair> earlier_;
  FeatureCacheWriter writer_;
  std::map<std::string, std::string> written_;  // StateOf what the file last says, by pair
  int resumed_ = 0;
};

// The watch loop: look, add the completed pairs, solve, say what changed, save; until idle or
// done.
class Watch {
 public:
  Watch(std::unique_ptr<CaptureFeed> feed, const CalibrationJobOptions& options,
        const WatchFlags& flags, fs::path session_path, EventStream* stream)
      : flags_(flags),
        options_(options),
        session_path_(std::move(session_path)),
        stream_(*stream),
        autosaver_(session_path_),
        cache_(session_path_),
        feed_(std::move(feed)) {}

  int Run() {
    double last_activity = SteadySeconds();
    for (;;) {
      const double now = SteadySeconds();
      bool added = false;
      const FeedUpdate update = feed_->Poll(now);
      // A recording that grows is alive even while no pair comes out of it (its board unknown).
      if (update.data_arrived) last_activity = now;
      for (const std::string& note : update.notes) stream_.Note("note", "", note);
      for (const FolderEvent& event : update.events) {
        last_activity = now;
        if (event.kind == FolderEvent::Kind::kPairComplete) {
          // The job starts with the first pair: a recording's camera and board are known then.
          if (!job_) StartJob();
          job_->AddPair(event.pair, cache_.Earlier(event.pair));
          added = true;
        } else {
          stream_.Note(event.kind == FolderEvent::Kind::kIncomplete ? "incomplete" : "removed",
                       event.stem, event.reason);
        }
      }
      if (added && SolveAndReport(now)) {
        stream_.Note("end", "", "done: the goal is met with a σ that can be trusted");
        return kOk;
      }
      if (update.closed) {
        stream_.Note("end", "", "the recording was closed by its recorder");
        return kOk;
      }
      if (flags_.idle_exit_s > 0 && SteadySeconds() - last_activity >= flags_.idle_exit_s) {
        stream_.Note(
            "end", "",
            "no new data for " + std::to_string(static_cast<int>(flags_.idle_exit_s)) + " s");
        return kOk;
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(flags_.poll_s));
    }
  }

 private:
  // The job over the feed's camera and board; the pairs it already holds join as new ones.
  void StartJob() {
    Dataset setup = *feed_->Setup();
    std::vector<PairEntry> known = std::move(setup.pairs);
    setup.pairs.clear();
    job_.emplace(std::move(setup), options_);
    for (const PairEntry& pair : known) job_->AddPair(pair, cache_.Earlier(pair));
  }

  // Solves, then says the verdicts that changed and the solve, and saves; true when the watch
  // should end (--exit-when-done and done). `looked_s`: when the new pairs were seen complete.
  bool SolveAndReport(double looked_s) {
    if (const std::string note = cache_.ResumedNote(); !note.empty())
      stream_.Note("resumed", "", note);
    job_->Solve();
    const CaptureAdvice& advice = job_->Advise();
    for (const std::string& failure : cache_.Record(*job_)) stream_.Note("error", "", failure);
    ReportVerdicts(advice);
    nlohmann::json solve = nlohmann::json::parse(CaptureAdviceJson(advice));
    solve["event"] = "solve";
    solve["latency_s"] = SteadySeconds() - looked_s;
    stream_.Emit(solve, HumanProgress(advice));
    try {
      autosaver_.Save(job_->ToSession(feed_->DatasetFolder()));
    } catch (const IoError& e) {
      stream_.Note("error", "", std::string("session not saved: ") + e.what());
    }
    return flags_.exit_when_done && advice.state && advice.state->done;
  }

  // The new pairs, and every earlier pair whose verdict this solve changed (a board found later
  // at the camera's prediction, a pair a better solution disagrees with).
  void ReportVerdicts(const CaptureAdvice& advice) {
    for (const PairAdvice& pair : advice.pairs) {
      const bool accepted = pair.status == PairStatus::kAccepted;
      const std::string reason = accepted ? "" : pair.reason;
      const auto verdict = std::make_pair(accepted, reason);
      const auto before = reported_.find(pair.id);
      if (before != reported_.end() && before->second == verdict) continue;
      reported_[pair.id] = verdict;
      stream_.Emit(
          {{"event", "pair"}, {"name", pair.id}, {"accepted", accepted}, {"reason", reason}},
          pair.id + ": " + (accepted ? "accepted" : PairStatusName(pair.status) + ": " + reason));
    }
  }

  const WatchFlags& flags_;
  CalibrationJobOptions options_;
  fs::path session_path_;
  EventStream& stream_;
  Autosaver autosaver_;
  FeatureCacheKeeper cache_;
  std::unique_ptr<CaptureFeed> feed_;
  std::optional<CalibrationJob> job_;
  std::map<std::string, std::pair<bool, std::string>> reported_;  // verdicts said, by pair
};

// `watch` on a recording: import's board, camera and topic flags, pairs written to --out.
int WatchRecording(WatchFlags* flags, const CalibrationJobOptions& options,
                   const std::string& board, const std::string& out, const std::string& camera_file,
                   EventStream& stream) {
  try {
    flags->board = BoardFromFlag(board);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "calibench watch: --board: %s\n", e.what());
    return kUsage;
  }
  if (!camera_file.empty()) flags->import.camera = LoadCameraFile(camera_file);
  flags->import.max_pairs = 0;  // a capture has no cap: every hold is a pair
  flags->out = out.empty() ? DefaultImportFolder(flags->source) : fs::path(out);
  fs::create_directories(flags->out);
  const fs::path session_path =
      flags->session.empty() ? flags->out / "calibench.session.json" : fs::path(flags->session);
  Watch watch(FollowRecording(flags->source, flags->out, flags->board, flags->import), options,
              *flags, session_path, &stream);
  return watch.Run();
}

// `watch` on a folder in the folder form (or a manifest's folder).
int WatchFolder(WatchFlags* flags_in, const CalibrationJobOptions& options, EventStream& stream) {
  WatchFlags& flags = *flags_in;
  std::error_code error;
  if (fs::is_regular_file(flags.source, error)) {  // a manifest, named: its folder is watched
    flags.manifest = ResolveDataset(flags.source, DatasetKind::kLidarCamera).path;
    flags.source = fs::absolute(flags.manifest).parent_path().string();
  }
  if (!fs::is_directory(flags.source, error)) {
    std::fprintf(stderr,
                 "calibench watch: %s is not a folder (watch follows a folder in the folder "
                 "form: clouds/, images/, camera.yaml, target.json)\n",
                 flags.source.c_str());
    return kInputError;
  }
  std::string not_yet;
  std::optional<Dataset> setup = WaitForSetup(flags, stream, &not_yet);
  if (!setup) {
    stream.Note("end", "", not_yet);
    std::fprintf(stderr, "calibench watch: error: %s\n", not_yet.c_str());
    return kInputError;
  }
  const fs::path session_path = flags.session.empty()
                                    ? fs::path(flags.source) / "calibench.session.json"
                                    : fs::path(flags.session);
  Watch watch(FollowFolder(std::move(*setup), flags.source, flags.folder), options, flags,
              session_path, &stream);
  return watch.Run();
}

// `watch --check`: the drift meter instead of the board capture, with the recording's flags.
int WatchWithDriftMeter(WatchCheckRequest drift, const WatchFlags& flags,
                        const std::string& camera_file) {
  drift.source = flags.source;
  drift.camera_file = camera_file;
  drift.json_lines = flags.json_lines;
  drift.exit_when_sure = flags.exit_when_done;
  drift.idle_exit_s = flags.idle_exit_s;
  drift.input.cloud_topic = flags.import.cloud_topic;
  drift.input.image_topic = flags.import.image_topic;
  drift.input.camera_info_topic = flags.import.camera_info_topic;
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
  WatchFlags flags;
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
  app.add_flag("--json-lines", flags.json_lines,
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
  if (!drift.result.empty()) return WatchWithDriftMeter(drift, flags, camera_file);
  std::string why;
  if (!FinalizePipelineFlags(pipeline, &why) || !flags.folder.Check(&why) ||
      !(flags.idle_exit_s >= 0)) {
    if (why.empty()) why = "--idle-exit must be >= 0 (seconds)";
    std::fprintf(stderr, "calibench watch: %s\n", why.c_str());
    return kUsage;
  }
  options.advise.pipeline = pipeline.options;
  options.warm_start = true;  // each solve from the last: the capture grows by one pair
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench watch: %s\n", why.c_str());
    return kUsage;
  }
  EventStream stream(flags.json_lines);
  if (IsRecordingSource(flags.source))
    return WatchRecording(&flags, options, board, out, camera_file, stream);
  return WatchFolder(&flags, options, stream);
}

}  // namespace calibench::app
