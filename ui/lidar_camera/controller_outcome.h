// The workbench's views of an outcome already solved, without a controller: the snapshot the
// panels read made from a CalibrationOutcome, and one pair's cloud, image and reprojection
// computed by the functions the controller runs for its selected pair. The report draws its
// figures from these (docs/architecture.md, "Views drawn from results"): no second controller,
// no second extraction, no second solve.
#pragma once

#include <memory>
#include <string>

#include "core/io/rig_folder.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/rig.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/state/view_state.h"

namespace calibench::ui {

// The cloud projected into the camera at cam_from_lidar, and the points the view's visibility
// mode keeps (hidden-point removal, z-buffer or all): what the camera view colours by depth.
std::shared_ptr<const Reprojection> ReprojectPair(const CameraModel& camera,
                                                  const Pose& cam_from_lidar,
                                                  const LidarCloud& cloud, const ViewState& view,
                                                  const std::string& pair_id);

// The snapshot a workbench shows once `outcome` is solved: every pair's planes, detection,
// status, residual and robust weight, the solution with the summary's notes. No pair is selected
// or loaded (OutcomePair below).
Snapshot SnapshotOfOutcome(const Dataset& dataset, const CalibrationOutcome& outcome);

// A rig's cameras around camera `active` (names, intrinsics, captures), before any solve.
RigView RigViewOf(const RigFolder& rig, size_t active);
// The rig solve's outcome into the rig's view: every camera's own solve (the open camera's only
// when `active_solved` is false: once it has a live solve, that one is shown) and the joint one.
void ApplyRigOutcome(const RigOutcome& outcome, bool active_solved, RigView* rig);

// One pair's heavy members as the controller holds them for its selection.
struct OutcomePair {
  std::shared_ptr<const LidarCloud> cloud;
  std::shared_ptr<const ImageU8> image;
  std::shared_ptr<const UndistortedView> undistorted;  // only when the view shows it undistorted
  std::shared_ptr<const Reprojection> reprojection;    // at the solution; null without one
};
// Reads pair `index`'s files (LoadPairInputs) and reprojects its cloud; nullopt with *why naming
// the file when they cannot be read. Safe to call from several threads at once.
// `undistorter`: the camera's (built once for many pairs); needed when the view shows the image
// undistorted.
std::optional<OutcomePair> LoadOutcomePair(const Snapshot& snapshot, int index,
                                           const Undistorter* undistorter, std::string* why);
// The pair's reprojection at the snapshot's solution (none without one), its files already held.
void ReprojectOutcomePair(const Snapshot& snapshot, int index, OutcomePair* pair);
// Selects pair `index` in the snapshot with its members (as SelectPair then the worker would).
void ShowOutcomePair(Snapshot* snapshot, int index, const OutcomePair& pair);

}  // namespace calibench::ui
