// What the views show of the selected pair, a task of the controller: selection, image,
// reprojection, the view's settings recorded (ui/lidar_camera/view_task.h).
#include "ui/lidar_camera/view_task.h"

#include "core/camera/undistort.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {

void ViewTask::Reproject(int index) {
  std::shared_ptr<const LidarCloud> cloud;
  std::optional<Pose> cam_from_lidar;
  CameraModel camera;
  ViewState view;
  std::string id;
  {
    std::lock_guard lock(host_.mutex);
    if (!host_.state.HasPair(index) || !host_.state.solver.result) return;
    cloud = host_.state.pairs.at(index).cloud;
    cam_from_lidar = host_.state.solver.result->cam_from_lidar;
    camera = host_.state.dataset->camera;
    view = host_.state.view;
    id = host_.state.pairs.at(index).id;
  }
  if (!cloud) return;
  auto reprojection = ReprojectPair(camera, *cam_from_lidar, *cloud, view, id);
  std::lock_guard lock(host_.mutex);
  host_.state.reprojection = reprojection;
  ++host_.state.generation;
}

void ViewTask::ShowImage() {
  std::filesystem::path path;
  const std::shared_ptr<const ImageU8> image = controls_.load_image(&path);
  if (!image) return;
  CameraModel camera;
  {
    std::lock_guard lock(host_.mutex);
    camera = host_.state.dataset->camera;
  }
  auto undistorted = std::make_shared<const UndistortedView>(Undistort(camera, *image));
  std::lock_guard lock(host_.mutex);
  if (!StillSelected(host_.state, path)) return;
  host_.state.selected_image = image;
  host_.state.selected_image_pair = host_.state.pairs.at(host_.state.selected).id;
  host_.state.selected_undistorted = undistorted;
  ++host_.state.generation;
  controls_.image_shown();
}

void ViewTask::Select(const SelectPair& select) {
  if (!host_.state.HasPair(select.index) || select.index == host_.state.selected) return;
  // Following a capture: looking at an older pair stops following; the newest resumes it.
  controls_.follow_newest(select.index + 1 == static_cast<int>(host_.state.pairs.size()));
  host_.state.selected = select.index;
  host_.state.selected_image.reset();
  host_.state.selected_undistorted.reset();
  host_.state.reprojection.reset();
  Record();
  host_.worker.Enqueue([this] { ShowImage(); });
  const int index = select.index;
  host_.worker.Enqueue([this, index] { Reproject(index); });
}

void ViewTask::Set(const SetView& view) {
  const bool visibility_changed =
      view.view.visibility != host_.state.view.visibility ||
      view.view.hpr_radius_exponent != host_.state.view.hpr_radius_exponent;
  host_.state.view = view.view;
  Record();
  if (visibility_changed) {
    const int index = host_.state.selected;
    host_.worker.Enqueue([this, index] { Reproject(index); });
  }
}

void ViewTask::Record() {
  host_.mutex.AssertHeld(__func__);
  CalibrationJob* job = controls_.job();
  if (!job) return;
  Snapshot& state = host_.state;
  const bool had_selected =
      state.selected >= 0 && state.selected < static_cast<int>(state.pairs.size());
  state.view.selected_pair = had_selected ? state.pairs.at(state.selected).id : "";
  const std::string view = ViewToJson(state.view);
  job->record().Edit([&](Session* session) { session->view_json = view; }, /*amend=*/true);
  controls_.edited();
}

}  // namespace calibench::ui
