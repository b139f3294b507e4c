// A rig's cameras beside the one open in the workbench (a task of the controller,
// ui/lidar_camera/controller.h): each camera's own solve and the rig's joint solve
// (core/lidar_camera/rig.h, as `calibrate` runs them), one step each, as background jobs on the
// worker below the edits' jobs; the meter over every camera; the strip of the selected capture's
// frames. What it shows lands in Snapshot::rig. No GL, GLFW or ImGui.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/io/rig_folder.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class RigTask {
 public:
  // `judge_meter` judges the workbench's meter again once the rig's outcome is in (called with
  // the mutex held).
  RigTask(TaskHost<Snapshot> host, std::function<void()> judge_meter)
      : host_(host), judge_meter_(std::move(judge_meter)) {}

  // Before another camera of the same rig opens: its cameras' solves as `rig` holds them (the
  // window's camera switch), so that they are not solved again. Locks the mutex.
  void Carry(const RigView& rig);
  // The rig view with camera `active` open (true: the other cameras' solves carried). Mutex held.
  bool SetUp(const RigFolder& rig, size_t active);
  // The rig solve as background steps (the rig read, each camera, the joint solve), the open
  // camera with `active_edits`, every camera with `options`; its outcome is published by the
  // last step. Nothing for a rig of one or while one runs. Mutex held.
  void Start(const PairEdits& active_edits, const PipelineOptions& options);
  // Drops the rig solve's steps; waits for a running one. Mutex not held.
  void Cancel();
  // Waits for the rig solve's steps (tests, renders). Mutex not held.
  void Wait();
  // The open camera's entry from the latest solve, and every camera's meter. Mutex held.
  void UpdateActiveCamera();
  // The strip's frames of the selected capture (worker, mutex not held).
  void LoadFrames();
  // SelectCamera: the window's to do (WindowShell::SelectCamera); said on the status line here.
  void Select(const SelectCamera& select);

 private:
  struct Run;                                                // one rig solve in progress
  void Step(const std::shared_ptr<Run>& run);                // worker, mutex not held
  void Publish(const Run& run, const std::string& failure);  // mutex not held

  TaskHost<Snapshot> host_;
  std::function<void()> judge_meter_;
  std::optional<RigView> carried_;                                    // Carry's, for the next SetUp
  std::map<std::string, std::shared_ptr<const ImageU8>> frames_;      // "<camera>/<pair>" (worker)
  std::vector<std::map<std::string, std::filesystem::path>> images_;  // per camera (mutex)
};

}  // namespace calibench::ui
