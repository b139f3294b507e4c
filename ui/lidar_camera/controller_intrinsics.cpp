// The workbench's camera intrinsics: estimated from the loaded pairs' board corners by the same
// step as `calibench intrinsics` (CalibrateIntrinsics), and written beside the dataset on request.
#include <cstdio>
#include <stdexcept>

#include "core/io/camera_file.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

template <>
void Controller::Handle(const EstimateIntrinsics& request) {
  if (!state_.dataset || state_.intrinsics_running) return;
  std::vector<IntrinsicsView> views;
  for (const PairView& pair : state_.pairs)
    if (pair.detection && !pair.detection->pixels.empty())
      views.push_back({pair.id, *pair.detection});
  const int width = state_.dataset->camera.width, height = state_.dataset->camera.height;
  state_.intrinsics_running = true;
  state_.intrinsics_failure.clear();
  SetStatus("estimating the camera's intrinsics from " + std::to_string(views.size()) +
                " pairs' corners...",
            false);
  worker_.Enqueue([this, views = std::move(views), width, height, model = request.model] {
    IntrinsicsOptions options;
    options.model = model;
    std::shared_ptr<const IntrinsicsResult> result;
    std::string failure;
    try {
      result = std::make_shared<const IntrinsicsResult>(
          CalibrateIntrinsics(views, width, height, options));
    } catch (const std::invalid_argument& e) {
      failure = e.what();
    }
    std::lock_guard lock(mutex_);
    state_.intrinsics_running = false;
    state_.intrinsics = result;
    state_.intrinsics_failure = failure;
    if (result) {
      char line[96];
      std::snprintf(line, sizeof(line),
                    "intrinsics: fx %.2f fy %.2f, RMS %.3f px: ", result->camera.fx,
                    result->camera.fy, result->rms_px);
      SetStatus(line + result->verdict, false);
    } else {
      SetStatus("intrinsics not estimated: " + failure, true);
    }
  });
}

template <>
void Controller::Handle(const SaveIntrinsics& request) {
  if (!state_.intrinsics || !state_.dataset) {
    SetStatus("no intrinsics to save: estimate them first", true);
    return;
  }
  std::filesystem::path path = request.path;
  const std::filesystem::path& manifest = state_.dataset->manifest;
  if (path.is_relative())
    path = (std::filesystem::is_directory(manifest) ? manifest : manifest.parent_path()) / path;
  try {
    SaveCameraFile(path, state_.intrinsics->camera, request.format);
  } catch (const IoError& e) {
    SetStatus(e.what(), true);
    return;
  }
  state_.intrinsics_saved = path;
  SetStatus("wrote the estimated intrinsics to " + path.string() +
                " (the dataset's camera is unchanged: point camera_file at it to use them)",
            false);
}

}  // namespace calibench::ui
