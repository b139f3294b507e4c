// The controller's rig: a rig camera opened in the views with the rig's other cameras beside it.
// Each camera's own solve and the rig's joint solve (core/lidar_camera/rig.h, as `calibrate` runs
// them), one step each, as background jobs on the worker (below the edits' jobs); the meter over
// every camera; the strip of the selected capture's frames.
#include <algorithm>

#include "core/io/image_io.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {

namespace {

constexpr int kRigFrameWidth = 160;  // pixels, as the pairs' thumbnails
const std::string kRigLane = "rig";  // the worker's background lane for the rig solve's steps
// A rig step extracts this many pairs per thread: about one pair's extraction (0.1-0.3 s for a
// pinhole camera's, up to 1.5 s for a fisheye pair the detector searches hard for).
constexpr size_t kPairsPerThreadAndStep = 1;

}  // namespace

// One rig solve in progress: its steps hold it (shared) from job to job.
struct Controller::RigRun {
  std::filesystem::path path;
  std::string active;
  RigEdits edits;
  PipelineOptions options;
  std::string notes;  // the other cameras' sessions that did not read
  std::optional<RigCalibration> calibration;
};

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

void Controller::CancelRigSolve() {
  worker_.CancelBackground(kRigLane);
  std::lock_guard lock(mutex_);
  if (state_.rig) state_.rig->solving = false;
}

void Controller::WaitRig() {
  while (worker_.BackgroundPending(kRigLane)) worker_.WaitIdle();
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
    carried.progress.clear();
    view = std::move(carried);
  }
  carried_rig_.reset();
  state_.rig = std::move(view);
  return carry;
}

void Controller::StartRigSolve() {
  mutex_.AssertHeld(__func__);
  if (!state_.rig || !state_.rig->Several() || state_.rig->solving) return;
  state_.rig->solving = true;
  state_.rig->progress = "waiting for the open camera's work";
  ++state_.generation;
  auto run = std::make_shared<RigRun>();
  run->path = state_.rig->path;
  run->active = state_.rig->cameras[state_.rig->active].name;
  if (job_) run->edits[run->active] = job_->record().Edits();
  run->options = state_.settings.Over(pipeline_);
  worker_.EnqueueBackground(kRigLane, [this, run] { RigStep(run); });
}

void Controller::RigStep(const std::shared_ptr<RigRun>& run) {
  std::string failure;
  try {
    if (!run->calibration) {
      const RigFolder rig = LoadRig(run->path);
      // The other cameras' edits: their sessions beside the rig, where the workbench left them.
      for (const std::string& name : rig.camera_names) {
        const std::filesystem::path session = DefaultSessionPath(run->path, name);
        std::error_code error;
        if (name == run->active || !std::filesystem::exists(session, error)) continue;
        try {
          run->edits[name] = EditsFromSession(LoadSession(session));
        } catch (const IoError& e) {
          run->notes += std::string(run->notes.empty() ? "" : "; ") + e.what();
        }
      }
      // A pair per thread and step: an edit waits for one pair's extraction at most.
      run->calibration.emplace(rig, run->options, run->edits, ProgressCallback{},
                               kPairsPerThreadAndStep);
    } else if (!run->calibration->Step()) {
      return PublishRigOutcome(*run, "");
    }
    // What the next step works on, for the strip; then the step itself, below the edits' jobs.
    const size_t c = run->calibration->NextCamera();
    const std::vector<std::string>& names = run->calibration->Outcome().camera_names;
    const std::string next = c < names.size()
                                 ? "camera " + names[c] + " (" + std::to_string(c + 1) + " of " +
                                       std::to_string(names.size()) + ")"
                                 : "the joint solve";
    {
      std::lock_guard lock(mutex_);
      if (!state_.rig || state_.rig->path != run->path) return;  // another rig opened since
      if (state_.rig->progress != next) {
        state_.rig->progress = next;
        ++state_.generation;
      }
    }
    worker_.EnqueueBackground(kRigLane, [this, run] { RigStep(run); });
    return;
  } catch (const std::exception& e) {  // IoError, or a filesystem error reading the rig
    failure = e.what();
  }
  PublishRigOutcome(*run, failure);
}

void Controller::PublishRigOutcome(const RigRun& run, const std::string& failure) {
  std::lock_guard lock(mutex_);
  if (!state_.rig || state_.rig->path != run.path) return;
  state_.rig->solving = false;
  state_.rig->progress.clear();
  if (failure.empty() && run.calibration) {
    ApplyRigOutcome(run.calibration->Outcome(), state_.solver.result.has_value(), &*state_.rig);
    JudgeMeter(/*record=*/false);
  } else {
    state_.rig->failure = failure;
  }
  if (!run.notes.empty())
    SetStatus("rig solve without some cameras' edits (their sessions did not read): " + run.notes,
              true);
  ++state_.generation;
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
  if (!state_.rig || !state_.rig->Several())
    return SetStatus("not a rig: there is one camera", true);
  SetStatus("switching to camera '" + select.camera +
                "' is the window's: open it with `calibench gui --dataset " +
                state_.rig->path.string() + " --camera " + select.camera + "`",
            true);
}

template <>
void Controller::Handle(const SolveRig&) {
  if (!state_.rig || !state_.rig->Several())
    return SetStatus("not a rig: there is one camera", true);
  StartRigSolve();
}

}  // namespace calibench::ui
