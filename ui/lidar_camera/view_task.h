// What the views show of the selected pair (a task of the controller,
// ui/lidar_camera/controller.h): the selection, its camera image decoded and undistorted on the
// worker, its cloud reprojected into the image at the solution (hidden points removed as the view
// asks), and the view's settings, recorded with the session but never an undo step (undo steps
// through edits only). No GL, GLFW or ImGui.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <utility>

#include "core/session/calibration_job.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class ViewTask {
 public:
  // What the controller does around the views.
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job (mutex)
    std::function<void()> edited;          // the record changed: autosave (mutex)
    // Following a capture: whether the views go on moving to each new pair (mutex).
    std::function<void(bool)> follow_newest;
    // The selected pair's image file, read (ControllerState::LoadSelectedImageFile; worker).
    std::function<std::shared_ptr<const ImageU8>(std::filesystem::path*)> load_image;
    std::function<void()> image_shown;  // the rig's other cameras' frames follow (mutex)
  };
  ViewTask(TaskHost<Snapshot> host, Controls controls)
      : host_(host), controls_(std::move(controls)) {}

  // SelectPair: the views move to the pair, its image and reprojection follow (mutex held).
  void Select(const SelectPair& select);
  // SetView: the view's settings; the reprojection again when visibility changed (mutex held).
  void Set(const SetView& view);
  // The view (the selected pair, the camera, visibility) into the record, amending the current
  // step (mutex held).
  void Record();
  // The selected pair's image decoded and undistorted (worker, mutex not held).
  void ShowImage();
  // Pair `index`'s cloud reprojected at the solution, when it is still selected (worker).
  void Reproject(int index);

 private:
  TaskHost<Snapshot> host_;
  Controls controls_;
};

}  // namespace calibench::ui
