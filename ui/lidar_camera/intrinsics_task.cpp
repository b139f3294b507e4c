#include "ui/lidar_camera/intrinsics_task.h"

#include <cstdio>
#include <stdexcept>

#include "core/io/camera_file.h"

namespace calibench::ui {

void IntrinsicsTask::Estimate(const EstimateIntrinsics& request) {
  Snapshot& state = host_.state;
  if (!state.dataset || state.intrinsics_running) return;
  std::vector<IntrinsicsView> views;
  for (const PairView& pair : state.pairs)
    if (pair.detection && !pair.detection->pixels.empty())
      views.push_back({pair.id, *pair.detection});
  const int width = state.dataset->camera.width, height = state.dataset->camera.height;
  state.intrinsics_running = true;
  state.intrinsics_failure.clear();
  host_.SetStatus("estimating the camera's intrinsics from " + std::to_string(views.size()) +
                      " pairs' corners...",
                  false);
  host_.worker.Enqueue([this, views = std::move(views), width, height, model = request.model] {
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
    std::lock_guard lock(host_.mutex);
    Snapshot& state = host_.state;
    state.intrinsics_running = false;
    state.intrinsics = result;
    state.intrinsics_failure = failure;
    if (result) {
      char line[96];
      std::snprintf(line, sizeof(line),
                    "intrinsics: fx %.2f fy %.2f, RMS %.3f px: ", result->camera.fx,
                    result->camera.fy, result->rms_px);
      host_.SetStatus(line + result->verdict, false);
    } else {
      host_.SetStatus("intrinsics not estimated: " + failure, true);
    }
  });
}

void IntrinsicsTask::Save(const SaveIntrinsics& request) {
  Snapshot& state = host_.state;
  if (!state.intrinsics || !state.dataset) {
    host_.SetStatus("no intrinsics to save: estimate them first", true);
    return;
  }
  std::filesystem::path path = request.path;
  const std::filesystem::path& manifest = state.dataset->manifest;
  if (path.is_relative())
    path = (std::filesystem::is_directory(manifest) ? manifest : manifest.parent_path()) / path;
  try {
    SaveCameraFile(path, state.intrinsics->camera, request.format);
  } catch (const IoError& e) {
    host_.SetStatus(e.what(), true);
    return;
  }
  state.intrinsics_saved = path;
  host_.SetStatus("wrote the estimated intrinsics to " + path.string() +
                      " (the dataset's camera is unchanged: point camera_file at it to use them)",
                  false);
}

}  // namespace calibench::ui
