#include "core/session/capture_follow.h"

#include <chrono>
#include <functional>
#include <map>
#include <thread>

#include "core/base/file_lock.h"
#include "core/capture/capture_feed.h"
#include "core/capture/recording_watch.h"
#include "core/io/dataset_source.h"
#include "core/session/feature_cache.h"
#include "core/session/session.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// One look for the capture's camera and target: the folder form's camera.yaml and target.json,
// or a LiDAR-camera manifest of any name in the folder (core/io/dataset_source.h). nullopt while
// neither is there (*why: what was looked for). Another kind of dataset is refused (IoError
// naming the command for it).
std::optional<Dataset> LookForSetup(const fs::path& folder, const fs::path& manifest,
                                    std::string* why) {
  std::error_code error;
  if (manifest.empty() && fs::exists(folder / "camera.yaml", error) &&
      fs::exists(folder / "target.json", error))
    return LoadFolderSetup(folder);
  const std::optional<DatasetSource> source =
      manifest.empty() ? RecogniseDataset(folder, why) : std::nullopt;
  if (!manifest.empty() || (source && !source->folder_form)) {
    const DatasetSource lidar_camera =
        ResolveDataset(manifest.empty() ? folder : manifest, DatasetKind::kLidarCamera);
    Dataset setup = LoadDataset(lidar_camera.path);
    setup.pairs.clear();
    setup.manifest = folder;
    return setup;
  }
  return std::nullopt;
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

// Whether `dataset` (a session's) is the capture in `folder`: the folder itself, or a manifest in
// it (the workbench opened the folder's manifest).
bool IsCaptureIn(const fs::path& dataset, const fs::path& folder) {
  const fs::path normal_folder = NormalizeSessionPath(folder);
  const fs::path normal_dataset = NormalizeSessionPath(dataset);
  return normal_dataset == normal_folder || normal_dataset.parent_path() == normal_folder;
}

// Locks the session as the workbench locks it (core/base/file_lock.h): a session open in a
// workbench is not followed into, or the two would overwrite each other's edits. False with *why
// when another process holds it.
bool LockFollowedSession(const fs::path& session, std::optional<FileLock>* lock,
                         const FollowSink& sink, std::string* why) {
  std::string holder;
  try {
    *lock = FileLock::TryLock(session, &holder);
  } catch (const IoError& e) {  // no lock file can be made: saving will fail and say so
    Say(sink, "note", "", std::string("cannot lock the session (") + e.what() + ")");
    return true;
  }
  if (*lock) return true;
  *why = session.string() + ": the session is open in a Calibench workbench (" + holder +
         "); close it there, or give watch another --session";
  return false;
}

// The loop: look, add the completed pairs, solve, say what changed, save; until idle or done.
class Follower {
 public:
  Follower(std::unique_ptr<CaptureFeed> feed, const CalibrationJobOptions& options,
           const CaptureFollowRequest& request, const fs::path& session_path,
           const FollowSink& sink)
      : request_(request),
        options_(options),
        sink_(sink),
        session_path_(session_path),
        autosaver_(session_path),
        cache_(session_path),
        feed_(std::move(feed)) {}

  void Run() {
    FeedHandlers handlers;
    handlers.open = [this](Dataset read, double seen_s) {
      StartJob(std::move(read));
      return !job_->dataset().pairs.empty() && SolveAndReport(seen_s);
    };
    handlers.add = [this](std::vector<PairEntry> pairs, double seen_s) {
      for (const PairEntry& pair : pairs) AddPair(pair);
      return SolveAndReport(seen_s);
    };
    switch (FollowFeed(*feed_, request_.Loop(), handlers, sink_)) {
      case FeedEnd::kDone:
        return Say(sink_, "end", "", "done: the goal is met with a σ that can be trusted");
      case FeedEnd::kClosed:
        return Say(sink_, "end", "", "the recording was closed by its recorder");
      case FeedEnd::kIdle:
        return Say(
            sink_, "end", "",
            "no new data for " + std::to_string(static_cast<int>(request_.idle_exit_s)) + " s");
      case FeedEnd::kStopped:
        return Say(sink_, "end", "", "stopped");
    }
  }

 private:
  // The job over the capture's camera and board, with the user's word from the session there; the
  // pairs the first look read join as new ones.
  void StartJob(Dataset read) {
    std::vector<PairEntry> known = std::move(read.pairs);
    read.pairs.clear();
    job_.emplace(std::move(read), options_);
    ResumeSession();
    for (const PairEntry& pair : known) AddPair(pair);
  }

  // A painted pair is detected from its brush again: the cache holds detection without it.
  void AddPair(const PairEntry& pair) {
    job_->AddPair(pair, job_->HasBrush(pair.id) ? nullptr : cache_.Earlier(pair));
  }

  // The session the workbench or an earlier watch left for this capture: its brushes, rejections
  // and solver settings hold here as there (one state, whichever front end wrote it). One of
  // another dataset, or one that does not load, is kept as the autosave's first backup.
  void ResumeSession() {
    std::error_code error;
    if (!fs::exists(session_path_, error)) return;
    const fs::path kept = SessionBackupPath(session_path_, 1);
    try {
      const Session saved = LoadSession(session_path_);
      if (!saved.camera.empty() || !IsCaptureIn(saved.dataset, feed_->DatasetFolder())) {
        Say(sink_, "note", "",
            session_path_.string() + " is a session of " + saved.dataset.string() +
                (saved.camera.empty() ? "" : " (camera " + saved.camera + ")") + ", not of " +
                feed_->DatasetFolder().string() + ": a new one starts, that one is kept as " +
                kept.string());
        return;
      }
      job_->Resume(saved);
      int brushed = 0, rejected = 0;
      for (const auto& [id, edit] : EditsFromSession(saved)) {
        brushed += edit.brush_pixels.has_value();
        rejected += edit.rejected;
      }
      const auto count = [](int n, const std::string& what) {
        return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
      };
      Say(sink_, "resumed", "",
          "the session in " + session_path_.string() + ": " + count(brushed, "painted board") +
              ", " + count(rejected, "rejected pair") + " and the solver settings hold here");
    } catch (const IoError& e) {
      Say(sink_, "note", "",
          std::string(e.what()) + ": a new session starts, that one is kept as " + kept.string());
    }
  }

  // Solves, then says the verdicts that changed and the solve, and saves; true when the watch
  // should end (exit_when_done and done). `looked_s`: when the new pairs were seen complete.
  bool SolveAndReport(double looked_s) {
    if (const std::string note = cache_.ResumedNote(); !note.empty())
      Say(sink_, "resumed", "", note);
    job_->Solve();
    const CaptureAdvice& advice = job_->Advise();
    for (const std::string& failure : cache_.Record(*job_)) Say(sink_, "error", "", failure);
    ReportVerdicts(advice);
    FollowEvent solve;
    solve.event = "solve";
    solve.advice = &advice;
    solve.latency_s = SteadySeconds() - looked_s;
    sink_(solve);
    try {
      autosaver_.Save(job_->ToSession(feed_->DatasetFolder()));
    } catch (const IoError& e) {
      Say(sink_, "error", "", std::string("session not saved: ") + e.what());
    }
    return request_.exit_when_done && advice.state && advice.state->done;
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
      FollowEvent e;
      e.event = "pair";
      e.name = pair.id;
      e.accepted = accepted;
      e.status = pair.status;
      e.reason = reason;
      sink_(e);
    }
  }

  const CaptureFollowRequest& request_;
  CalibrationJobOptions options_;
  const FollowSink& sink_;
  fs::path session_path_;
  Autosaver autosaver_;
  FeatureCacheKeeper cache_;
  std::unique_ptr<CaptureFeed> feed_;
  std::optional<CalibrationJob> job_;
  std::map<std::string, std::pair<bool, std::string>> reported_;  // verdicts said, by pair
};

}  // namespace

FeedLoopOptions CaptureFollowRequest::Loop() const {
  FeedLoopOptions loop;
  loop.poll_s = poll_s;
  loop.idle_exit_s = idle_exit_s;
  return loop;
}

bool CaptureFollowRequest::Check(std::string* why) const {
  return folder.Check(why) && Loop().Check(why);
}

CaptureFeedOpener::CaptureFeedOpener(CaptureFollowRequest request, FollowSink sink)
    : request_(std::move(request)), sink_(std::move(sink)), start_s_(SteadySeconds()) {}

std::optional<OpenedFeed> CaptureFeedOpener::Try(std::string* why) {
  why->clear();
  if (IsRecordingSource(request_.source)) {
    // A recording: import's pairs, written to the dataset folder; a capture has no cap.
    request_.import.max_pairs = 0;
    if (request_.out.empty()) request_.out = DefaultImportFolder(request_.source);
    fs::create_directories(request_.out);
    const fs::path session =
        request_.session.empty() ? request_.out / "calibench.session.json" : request_.session;
    return OpenedFeed{
        FollowRecording(request_.source, request_.out, request_.board, request_.import), session};
  }
  if (!resolved_) {
    folder_ = request_.source;
    std::error_code error;
    if (fs::is_regular_file(folder_, error)) {  // a manifest, named: its folder is watched
      manifest_ = ResolveDataset(folder_, DatasetKind::kLidarCamera).path;
      folder_ = fs::absolute(manifest_).parent_path();
    }
    if (!fs::is_directory(folder_, error)) {
      *why = folder_.string() +
             " is not a folder (watch follows a folder in the folder form: clouds/, images/, "
             "camera.yaml, target.json)";
      return std::nullopt;
    }
    folder_ = fs::absolute(folder_);
    resolved_ = true;
  }
  std::string looked_for;
  std::optional<Dataset> setup = LookForSetup(folder_, manifest_, &looked_for);
  if (!setup) {
    // A capture script may write the camera and the target after starting: waited for.
    if (!said_)
      Say(sink_, "waiting", "",
          "waiting for camera.yaml and target.json (or a dataset manifest) in " + folder_.string());
    said_ = true;
    if (request_.idle_exit_s > 0 && SteadySeconds() - start_s_ >= request_.idle_exit_s) {
      // Never empty: an empty *why means "still waiting" to the caller.
      *why = looked_for.empty()
                 ? "no camera.yaml and target.json (nor a dataset manifest) came to " +
                       folder_.string()
                 : looked_for;
      Say(sink_, "end", "", *why);  // the camera and the target never came
    }
    return std::nullopt;
  }
  const fs::path session =
      request_.session.empty() ? folder_ / "calibench.session.json" : request_.session;
  return OpenedFeed{FollowFolder(std::move(*setup), folder_, request_.folder), session};
}

std::optional<OpenedFeed> OpenCaptureFeed(CaptureFollowRequest request, const FollowSink& sink,
                                          const std::function<bool()>& stopped, std::string* why) {
  const double poll_s = request.poll_s;
  const std::string source = request.source;
  CaptureFeedOpener opener(std::move(request), sink);
  for (;;) {
    if (std::optional<OpenedFeed> opened = opener.Try(why)) return opened;
    if (!why->empty()) return std::nullopt;
    if (stopped && stopped()) {
      *why = "stopped while waiting for the camera and the target of " + source;
      Say(sink, "end", "", *why);
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
}

bool FollowCapture(CaptureFollowRequest request, const CalibrationJobOptions& options,
                   const FollowSink& sink, std::string* why) {
  if (!request.Check(why)) return false;
  std::optional<OpenedFeed> opened = OpenCaptureFeed(request, sink, nullptr, why);
  if (!opened) return false;
  std::optional<FileLock> lock;
  if (!LockFollowedSession(opened->session, &lock, sink, why)) return false;
  Follower(std::move(opened->feed), options, request, opened->session, sink).Run();
  return true;
}

}  // namespace calibench
