// What both workbench controllers keep the same way: the snapshot the panels read, behind a
// mutex, with its status line and change counter, and the worker that runs the slow jobs.
// No GL, no ImGui.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include "core/base/image.h"
#include "core/io/image_io.h"
#include "core/results/pair_status.h"
#include "ui/state/checked_mutex.h"
#include "ui/state/work_queue.h"

namespace calibench::ui {

// The part of a pair every workbench lists: which pair, where it stands and why.
using PairHeader = PairStanding;

// The part of a snapshot every workbench shows: the status line and whether work is running.
struct SnapshotHeader {
  std::uint64_t generation = 0;  // increases with every change
  bool busy = false;             // the worker has queued or running jobs
  std::string status_line;       // the last message for the user (errors included)
  bool status_is_error = false;
};

// What a controller's task reaches of its controller: a task is a class of its own owning its own
// fields (the lidar-camera workbench's rig solve, targetless check, intrinsics), which the
// controller's Apply routes intents to. It sees the state under the controller's mutex, the
// worker its jobs run on, and the status line; nothing else. A task lives as long as its
// controller, whose destructor stops the worker before the tasks go.
template <typename Snapshot>
struct TaskHost {
  CheckedMutex& mutex;  // guards `state`
  Snapshot& state;
  WorkQueue& worker;
  // The user's message; call with mutex held.
  void SetStatus(const std::string& message, bool error) const {
    mutex.AssertHeld(__func__);
    state.status_line = message;
    state.status_is_error = error;
    ++state.generation;
  }
};

// True while `path` is still the selected pair's image in `state` (a newer selection drops the
// old image); with the controller's mutex held.
template <typename Snapshot>
bool StillSelected(const Snapshot& state, const std::filesystem::path& path) {
  return state.selected >= 0 && state.dataset->pairs[state.selected].image == path;
}

// Snapshot derives from SnapshotHeader. A derived controller must call StopWorker() first in its
// destructor: queued jobs touch the derived controller's members.
template <typename Snapshot>
class ControllerState {
 public:
  // A copy of the state for the panels (taken under the lock).
  Snapshot GetSnapshot() const {
    Snapshot copy;
    {
      std::lock_guard lock(mutex_);
      copy = state_;
    }
    copy.busy = worker_.Busy();
    return copy;
  }
  // The change counter alone (cheap: a window polls it to redraw when a thread changed the state).
  std::uint64_t Generation() const {
    std::lock_guard lock(mutex_);
    return state_.generation;
  }
  // Blocks until the worker has no queued or running job (tests, headless renders).
  void WaitIdle() { worker_.WaitIdle(); }

 protected:
  ControllerState()
      : worker_([this](const std::string& message) {
          std::lock_guard lock(mutex_);
          OnJobError();
          SetStatus("error: " + message, true);
        }) {}
  ~ControllerState() = default;

  void StopWorker() { worker_.Stop(); }
  // The user's message; call with mutex_ held.
  void SetStatus(const std::string& message, bool error) { Host().SetStatus(message, error); }
  // What a task of the controller reaches (TaskHost).
  TaskHost<Snapshot> Host() { return {mutex_, state_, worker_}; }
  // The selected pair's image, read on the worker: *path gets its file (empty when nothing with
  // an image is selected); nullptr with the status line set when the file cannot be read.
  std::shared_ptr<const ImageU8> LoadSelectedImageFile(std::filesystem::path* path) {
    {
      std::lock_guard lock(mutex_);
      if (state_.selected < 0 || !state_.dataset) return nullptr;
      *path = state_.dataset->pairs[state_.selected].image;
    }
    if (path->empty()) return nullptr;
    if (decoded_image_ && decoded_image_path_ == *path) return std::move(decoded_image_);
    try {
      return std::make_shared<const ImageU8>(LoadImage(*path));
    } catch (const IoError& e) {
      std::lock_guard lock(mutex_);
      SetStatus(e.what(), true);
      return nullptr;
    }
  }
  // An image a job has just decoded (worker thread): the next LoadSelectedImageFile of that path
  // takes it instead of decoding the file again.
  void KeepDecodedImage(const std::filesystem::path& path, std::shared_ptr<const ImageU8> image) {
    decoded_image_path_ = path;
    decoded_image_ = std::move(image);
  }
  // What else a failed job resets (with mutex_ held), before its message is shown.
  virtual void OnJobError() {}

  // Guards state_ and what each controller marks "(mutex_)"; the functions documented "call with
  // mutex_ held" check it (CheckedMutex::AssertHeld).
  mutable CheckedMutex mutex_;
  Snapshot state_;
  WorkQueue worker_;

 private:
  std::filesystem::path decoded_image_path_;  // worker thread only
  std::shared_ptr<const ImageU8> decoded_image_;
};

}  // namespace calibench::ui
