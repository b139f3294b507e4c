// The controller's rig: a rig camera opened in the views with the rig's other cameras beside it.
// Each camera's own solve and the rig's joint solve (core/lidar_camera/rig.h, as `calibrate` runs
// them) on a thread of their own; the meter over every camera; the strip of the selected capture's
// frames.
#include <algorithm>

#include "core/io/image_io.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {

namespace {

constexpr int kRigFrameWidth = 160;  // pixels, as the pairs' thumbnails

}  // namespace

bool RigView::AllDone() const {
  return !cameras.empty() && std::all_of(cameras.begin(), cameras.end(), [](const auto& camera) {
    return camera.meter && camera.meter->done;
  });
}

bool RigView::JointStale() const {
  return std::any_of(cameras.begin(), cameras.end(), [](const RigCameraView& camera) {
    return camera.single_at_joint && camera.single &&
           (camera.single->cam_from_lidar.matrix() - camera.single_at_joint->matrix()).norm() >
               1e-9;
  });
}

void Controller::CarryRig(const RigView& rig) {
  std::lock_guard lock(mutex_);
  carried_rig_ = rig;
}

void Controller::WaitRig() {
  if (rig_thread_.joinable()) rig_thread_.join();
}

bool Controller::SetUpRig(const RigFolder& rig, size_t active) {
  mutex_.AssertHeld(__func__);
  RigView view = RigViewOf(rig, active);
  rig_images_.assign(rig.cameras.size(), {});
  for (size_t c = 0; c < rig.cameras.size(); ++c)
    for (const PairEntry& pair : rig.cameras[c].pairs) rig_images_[c][pair.id] = pair.image;
  // A camera switch carries the other cameras' solves: the same rig, the same cameras.
  const bool carry = carried_rig_ && carried_rig_->path == view.path &&
                     carried_rig_->cameras.size() == view.cameras.size();
  if (carry) {
    RigView carried = std::move(*carried_rig_);
    carried.active = view.active;
    carried.cameras[active].single.reset();  // its live solve takes over, once there is one
    carried.cameras[active].meter.reset();
    for (RigCameraView& camera : carried.cameras) camera.frame.reset();
    carried.frames_pair.clear();
    carried.solving = false;
    view = std::move(carried);
  }
  carried_rig_.reset();
  state_.rig = std::move(view);
  return carry;
}

void Controller::StartRigSolve() {
  mutex_.AssertHeld(__func__);
  if (!state_.rig || state_.rig->solving) return;
  // Not solving: the last run has set that under mutex_ and does nothing after it.
  if (rig_thread_.joinable()) rig_thread_.join();
  state_.rig->solving = true;
  ++state_.generation;
  const std::filesystem::path path = state_.rig->path;
  const std::string active = state_.rig->cameras[state_.rig->active].name;
  RigEdits edits;
  if (job_) edits[active] = job_->record().Edits();
  const PipelineOptions options = PipelineOptionsFromState();
  rig_thread_ = std::thread([this, path, active, edits, options]() mutable {
    std::optional<RigOutcome> outcome;
    std::string failure, notes;
    try {
      const RigFolder rig = LoadRig(path);
      // The other cameras' edits: their sessions beside the rig, where the workbench left them.
      for (const std::string& name : rig.camera_names) {
        const std::filesystem::path session = DefaultSessionPath(path, name);
        std::error_code error;
        if (name == active || !std::filesystem::exists(session, error)) continue;
        try {
          edits[name] = EditsFromSession(LoadSession(session));
        } catch (const IoError& e) {
          notes += std::string(notes.empty() ? "" : "; ") + e.what();
        }
      }
      outcome = CalibrateRig(rig, options, {}, edits);
    } catch (const std::exception& e) {  // IoError, or a filesystem error reading the rig
      failure = e.what();
    }
    std::lock_guard lock(mutex_);
    if (!state_.rig || state_.rig->path != path) return;
    state_.rig->solving = false;
    if (outcome) {
      ApplyRigOutcome(*outcome, state_.solver.result.has_value(), &*state_.rig);
      JudgeMeter(/*record=*/false);
    } else {
      state_.rig->failure = failure;
    }
    if (!notes.empty())
      SetStatus("rig solve without some cameras' edits (their sessions did not read): " + notes,
                true);
    ++state_.generation;
  });
}

void Controller::UpdateActiveRigCamera() {
  mutex_.AssertHeld(__func__);
  if (!state_.rig) return;
  RigCameraView& active = state_.rig->cameras[state_.rig->active];
  if (state_.solver.result) {
    active.single = std::make_shared<const SolverResult>(*state_.solver.result);
    active.pairs_used = state_.meter ? state_.meter->pairs_used : 0;
    active.failure.clear();
  }
  for (RigCameraView& camera : state_.rig->cameras)
    if (&camera == &active && state_.solver.result)
      camera.meter = state_.meter;
    else if (camera.single)
      camera.meter =
          JudgeCapture(*camera.single, camera.pairs_used, state_.goal, StopRuleOptions{});
    else
      camera.meter.reset();
}

void Controller::LoadRigFrames() {
  std::string pair;
  std::vector<std::pair<std::string, std::filesystem::path>> wanted;  // key, image
  std::shared_ptr<const ImageU8> own;
  int active = 0;
  {
    std::lock_guard lock(mutex_);
    if (!state_.rig || state_.selected < 0) return;
    pair = state_.pairs[state_.selected].id;
    own = state_.pairs[state_.selected].thumbnail;
    active = state_.rig->active;
    for (size_t c = 0; c < rig_images_.size(); ++c) {
      const auto image = rig_images_[c].find(pair);
      wanted.emplace_back(state_.rig->cameras[c].name + "/" + pair,
                          image == rig_images_[c].end() ? std::filesystem::path() : image->second);
    }
  }
  std::vector<std::shared_ptr<const ImageU8>> frames;
  for (size_t c = 0; c < wanted.size(); ++c) {
    const auto& [key, image] = wanted[c];
    if (static_cast<int>(c) == active && own) {
      frames.push_back(own);
      continue;
    }
    if (image.empty()) {
      frames.push_back(nullptr);
      continue;
    }
    auto& cached = rig_frames_[key];
    if (!cached) {
      try {
        cached = std::make_shared<const ImageU8>(ResizeImage(LoadImage(image), kRigFrameWidth));
      } catch (const IoError& e) {
        std::lock_guard lock(mutex_);
        SetStatus(e.what(), true);
      }
    }
    frames.push_back(cached);
  }
  std::lock_guard lock(mutex_);
  if (!state_.rig || state_.selected < 0 || state_.pairs[state_.selected].id != pair) return;
  for (size_t c = 0; c < frames.size() && c < state_.rig->cameras.size(); ++c)
    state_.rig->cameras[c].frame = frames[c];
  state_.rig->frames_pair = pair;
  ++state_.generation;
}

template <>
void Controller::Handle(const SelectCamera& select) {
  if (!state_.rig) return SetStatus("not a rig: there is one camera", true);
  SetStatus("switching to camera '" + select.camera +
                "' is the window's: open it with `calibench gui --dataset " +
                state_.rig->path.string() + " --camera " + select.camera + "`",
            true);
}

template <>
void Controller::Handle(const SolveRig&) {
  if (!state_.rig) return SetStatus("not a rig: there is one camera", true);
  StartRigSolve();
}

}  // namespace calibench::ui
