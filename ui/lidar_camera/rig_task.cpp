#include "ui/lidar_camera/rig_task.h"

#include <algorithm>

#include "core/io/image_io.h"
#include "core/lidar_camera/rig.h"
#include "core/session/session.h"
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
struct RigTask::Run {
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

void RigTask::Carry(const RigView& rig) {
  std::lock_guard lock(host_.mutex);
  carried_ = rig;
}

void RigTask::Cancel() {
  host_.worker.CancelBackground(kRigLane);
  std::lock_guard lock(host_.mutex);
  if (host_.state.rig) host_.state.rig->solving = false;
}

void RigTask::Wait() {
  while (host_.worker.BackgroundPending(kRigLane)) host_.worker.WaitIdle();
}

bool RigTask::SetUp(const RigFolder& rig, size_t active) {
  host_.mutex.AssertHeld(__func__);
  RigView view = RigViewOf(rig, active);
  images_.assign(rig.cameras.size(), {});
  for (size_t c = 0; c < rig.cameras.size(); ++c)
    for (const PairEntry& pair : rig.cameras[c].pairs) images_[c][pair.id] = pair.image;
  // A camera switch carries the other cameras' solves: the same rig, the same cameras.
  const bool carry =
      carried_ && carried_->path == view.path && carried_->cameras.size() == view.cameras.size();
  if (carry) {
    RigView carried = std::move(*carried_);
    carried.active = view.active;
    carried.cameras[active].single.reset();  // its live solve takes over, once there is one
    carried.cameras[active].meter.reset();
    for (RigCameraView& camera : carried.cameras) camera.frame.reset();
    carried.frames_pair.clear();
    carried.solving = false;
    carried.progress.clear();
    view = std::move(carried);
  }
  carried_.reset();
  host_.state.rig = std::move(view);
  return carry;
}

void RigTask::Start(const PairEdits& active_edits, const PipelineOptions& options) {
  host_.mutex.AssertHeld(__func__);
  Snapshot& state = host_.state;
  if (!state.rig || !state.rig->Several() || state.rig->solving) return;
  state.rig->solving = true;
  state.rig->progress = "waiting for the open camera's work";
  ++state.generation;
  auto run = std::make_shared<Run>();
  run->path = state.rig->path;
  run->active = state.rig->cameras[state.rig->active].name;
  run->edits[run->active] = active_edits;
  run->options = options;
  host_.worker.EnqueueBackground(kRigLane, [this, run] { Step(run); });
}

void RigTask::Step(const std::shared_ptr<Run>& run) {
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
      return Publish(*run, "");
    }
    // What the next step works on, for the strip; then the step itself, below the edits' jobs.
    const size_t c = run->calibration->NextCamera();
    const std::vector<std::string>& names = run->calibration->Outcome().camera_names;
    const std::string next = c < names.size()
                                 ? "camera " + names[c] + " (" + std::to_string(c + 1) + " of " +
                                       std::to_string(names.size()) + ")"
                                 : "the joint solve";
    {
      std::lock_guard lock(host_.mutex);
      std::optional<RigView>& shown = host_.state.rig;
      if (!shown || shown->path != run->path) return;  // another rig opened since
      if (shown->progress != next) {
        shown->progress = next;
        ++host_.state.generation;
      }
    }
    host_.worker.EnqueueBackground(kRigLane, [this, run] { Step(run); });
    return;
  } catch (const std::exception& e) {  // IoError, or a filesystem error reading the rig
    failure = e.what();
  }
  Publish(*run, failure);
}

void RigTask::Publish(const Run& run, const std::string& failure) {
  std::lock_guard lock(host_.mutex);
  Snapshot& state = host_.state;
  if (!state.rig || state.rig->path != run.path) return;
  state.rig->solving = false;
  state.rig->progress.clear();
  if (failure.empty() && run.calibration) {
    ApplyRigOutcome(run.calibration->Outcome(), state.solver.result.has_value(), &*state.rig);
    judge_meter_();
  } else {
    state.rig->failure = failure;
  }
  if (!run.notes.empty())
    host_.SetStatus(
        "rig solve without some cameras' edits (their sessions did not read): " + run.notes, true);
  ++state.generation;
}

void RigTask::UpdateActiveCamera() {
  host_.mutex.AssertHeld(__func__);
  Snapshot& state = host_.state;
  if (!state.rig) return;
  RigCameraView& active = state.rig->cameras[state.rig->active];
  if (state.solver.result) {
    active.single = std::make_shared<const SolverResult>(*state.solver.result);
    active.pairs_used = state.meter ? state.meter->pairs_used : 0;
    active.failure.clear();
  }
  for (RigCameraView& camera : state.rig->cameras)
    if (&camera == &active && state.solver.result)
      camera.meter = state.meter;
    else if (camera.single)
      camera.meter = JudgeCapture(*camera.single, camera.pairs_used, state.goal, StopRuleOptions{});
    else
      camera.meter.reset();
}

void RigTask::LoadFrames() {
  Snapshot& state = host_.state;
  std::string pair;
  std::vector<std::pair<std::string, std::filesystem::path>> wanted;  // key, image
  std::shared_ptr<const ImageU8> own;
  int active = 0;
  {
    std::lock_guard lock(host_.mutex);
    if (!state.rig || state.selected < 0) return;
    pair = state.pairs[state.selected].id;
    own = state.pairs[state.selected].thumbnail;
    active = state.rig->active;
    for (size_t c = 0; c < images_.size(); ++c) {
      const auto image = images_[c].find(pair);
      wanted.emplace_back(state.rig->cameras[c].name + "/" + pair,
                          image == images_[c].end() ? std::filesystem::path() : image->second);
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
    auto& cached = frames_[key];
    if (!cached) {
      try {
        cached = std::make_shared<const ImageU8>(ResizeImage(LoadImage(image), kRigFrameWidth));
      } catch (const IoError& e) {
        std::lock_guard lock(host_.mutex);
        host_.SetStatus(e.what(), true);
      }
    }
    frames.push_back(cached);
  }
  std::lock_guard lock(host_.mutex);
  if (!state.rig || state.selected < 0 || state.pairs[state.selected].id != pair) return;
  for (size_t c = 0; c < frames.size() && c < state.rig->cameras.size(); ++c)
    state.rig->cameras[c].frame = frames[c];
  state.rig->frames_pair = pair;
  ++state.generation;
}

void RigTask::Select(const SelectCamera& select) {
  host_.mutex.AssertHeld(__func__);
  const std::optional<RigView>& rig = host_.state.rig;
  if (!rig || !rig->Several()) return host_.SetStatus("not a rig: there is one camera", true);
  host_.SetStatus("switching to camera '" + select.camera +
                      "' is the window's: open it with `calibench gui --dataset " +
                      rig->path.string() + " --camera " + select.camera + "`",
                  true);
}

}  // namespace calibench::ui
