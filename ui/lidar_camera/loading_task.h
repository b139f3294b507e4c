// The pairs' loading (a task of the controller, ui/lidar_camera/controller.h): each pair's files
// read by the job on the worker, the selected pair first; the board's detection once every cloud
// is in (with the scene's background, as `calibench calibrate` finds it); a pair's LiDAR board
// fitted again after its brush changed; a followed capture's pairs joining as they land, the views
// following the newest. What loading refused and how the session was opened go to the status line
// once the pairs are in. No GL, GLFW or ImGui.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/session/calibration_job.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/guidance_task.h"

namespace calibench::ui {

class LoadingTask {
 public:
  // What the controller does as pairs load (mutex held).
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job
    std::function<void()> publish;         // the job's records into the view (Publish)
    // Every board fitted or detected: the statuses the job recorded autosaved, a solve asked for.
    std::function<void()> settled;
    std::function<void()> show_image;    // the selected pair's image decoded, on the worker
    std::function<void(int)> reproject;  // pair `index`'s reprojection, on the worker
    // A camera image the job has just decoded, for the camera view to take (KeepDecodedImage).
    std::function<void(const std::filesystem::path&, std::shared_ptr<const ImageU8>)> keep_image;
  };
  LoadingTask(TaskHost<Snapshot> host, GuidanceTask& guidance, Controls controls)
      : host_(host), guidance_(guidance), controls_(std::move(controls)) {}

  // The opened dataset's pairs (the state's, the job's) loaded on the worker, the selected one
  // first; `note` (how the session was opened) joins the status line once they have. Mutex held.
  void Start(const std::string& note);
  // One pair more (a followed capture's), loaded and detected on the worker; a pair already
  // listed is left alone. Mutex held.
  void Add(const PairEntry& entry);
  // All pairs loaded, or in a followed capture those it opened with (mutex held).
  bool Settled() const;
  // Following a capture: whether the views move to each new pair (looking at an older pair
  // stops it, the newest resumes it). Mutex held.
  void FollowNewest(bool on) { follow_newest_ = on; }
  // Pair `index`'s LiDAR board fitted again from its brush or seed, or detected (worker; mutex
  // not held).
  void Refit(int index);

 private:
  void Load(int index);  // worker
  // After the last pair loaded: detection, the status line with what loading noted or refused,
  // the reopened session's reprojection and meter. Mutex held.
  void OnAllLoaded();
  // A followed capture's views move to its newest pair `index` once loaded (mutex held).
  bool FollowsTo(int index) const;
  // Load's part for a followed capture: the views follow, the pair is matched against the ghost
  // board shown while it was taken (mutex held).
  void OnLiveLoaded(int index);
  // After pair `index` loaded: its board refitted from its brush or seed (true: now, by the
  // caller, as the selected pair), or left to detection. Mutex held.
  bool ScheduleBoard(int index);
  // The background model over the loaded clouds, then detection where no seed or brush is.
  void DetectWithBackground();  // worker

  TaskHost<Snapshot> host_;
  GuidanceTask& guidance_;
  Controls controls_;
  std::string open_note_;                   // how the session was opened (mutex)
  std::vector<std::string> load_warnings_;  // what loading refused, for the status line (mutex)
  bool follow_newest_ = true;               // (mutex)
  bool opened_pairs_loaded_ = false;        // every pair Start began with has loaded (mutex)
};

}  // namespace calibench::ui
