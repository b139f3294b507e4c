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
  // The 3D view turned onto the selected pair (FramedOn): its board's inliers once the board is
  // found, its cloud's bulk before. Done when the selection moves to another pair and again when
  // what it is framed on improves (the cloud loaded, the board found: after each Publish), unless
  // the user has turned the view since; always when `forced` (FrameView). Not an edit: the
  // session records the orbit with the user's next change of the view. Mutex held.
  void Frame(bool forced);
  // The view restored from the session (open, undo, redo): an orbit of its own (saved by the
  // user's turn, or as framed when recorded) is kept until the selection moves; the default
  // one is framed. Mutex held.
  void Restored();
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
  // What the view was last framed on: the pair, how well (0 nothing, 1 its cloud, 2 its board),
  // and the view as framed (a view that differs from it was turned by the user).
  struct Framed {
    std::string pair_id;
    int quality = 0;
    ViewState view;
  } framed_;
};

}  // namespace calibench::ui
