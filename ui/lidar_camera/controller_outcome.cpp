#include "ui/lidar_camera/controller_outcome.h"

#include <algorithm>

#include "core/camera/undistort.h"
#include "core/lidar_camera/result_io.h"
#include "core/reproject/reproject.h"

namespace calibench::ui {

std::shared_ptr<const Reprojection> ReprojectPair(const CameraModel& camera,
                                                  const Pose& cam_from_lidar,
                                                  const LidarCloud& cloud, const ViewState& view,
                                                  const std::string& pair_id) {
  auto reprojection = std::make_shared<Reprojection>();
  reprojection->pair_id = pair_id;
  reprojection->points = ProjectCloud(camera, cam_from_lidar, cloud);
  if (view.visibility == VisibilityMode::kHpr) {
    std::vector<Vec3> in_cam;
    in_cam.reserve(reprojection->points.size());
    for (const ProjectedPoint& p : reprojection->points)
      in_cam.push_back(cam_from_lidar * cloud.points[p.index].cast<double>());
    HprOptions options;
    options.radius_exponent = view.hpr_radius_exponent;
    reprojection->visible = HiddenPointRemoval(in_cam, options);
  } else if (view.visibility == VisibilityMode::kZBuffer) {
    reprojection->visible = ZBufferVisibility(camera, reprojection->points, ZBufferOptions{});
  } else {
    reprojection->visible.assign(reprojection->points.size(), true);
  }
  return reprojection;
}

Snapshot SnapshotOfOutcome(const Dataset& dataset, const CalibrationOutcome& outcome) {
  Snapshot s;
  s.dataset = dataset;
  s.dataset_path = dataset.manifest;
  // One camera is a rig of one, as the controller sees it; a rig's report replaces it.
  s.rig = RigViewOf(RigOfOne(dataset), 0);
  if (outcome.solution)
    s.rig->cameras[0].single = std::make_shared<const SolverResult>(*outcome.solution);
  // The solution's residuals and weights follow its accepted pairs in order (SolveExtractedPairs).
  size_t solved = 0;
  std::vector<PairView> pairs;
  for (const PairFeatures& features : outcome.pairs) {
    PairView pair;
    static_cast<PairStanding&>(pair) = features;
    pair.lidar = features.lidar;
    pair.board_origin = features.board_origin;
    // Its inliers drawn as a found board's (cyan) unless a brush or seed chose them.
    pair.brush_origin = features.board_origin.source == BoardSource::kBrush ? BrushOrigin::kPainted
                        : features.board_origin.source == BoardSource::kSeed
                            ? BrushOrigin::kSeeded
                            : BrushOrigin::kDetected;
    pair.camera = features.camera;
    if (features.camera) pair.detection = features.camera->corners;
    if (!features.lidar) pair.lidar_failure = features.reason;
    if (!features.camera) pair.camera_failure = features.reason;
    if (outcome.solution && features.status == PairStatus::kAccepted) {
      const SolverResult& result = *outcome.solution;
      if (solved < result.residuals.size()) pair.residual = result.residuals[solved];
      if (solved < result.robust_weights.size()) pair.robust_weight = result.robust_weights[solved];
      s.solver.solved_pair_ids.push_back(features.id);
      ++solved;
    }
    pairs.push_back(std::move(pair));
  }
  s.pairs = SharedPairs<PairView>(std::move(pairs));
  if (outcome.solution) {
    s.solver.result = outcome.solution;
    for (const std::string& note : {DescribeLidarModel(outcome), DescribeLearnedLidarNoise(outcome),
                                    CountResiduals(outcome).note})
      if (!note.empty()) s.solver.notes.push_back(note);
  } else {
    s.solver.failure = outcome.failure;
  }
  return s;
}

std::optional<OutcomePair> LoadOutcomePair(const Snapshot& snapshot, int index,
                                           const Undistorter* undistorter, std::string* why) {
  const Dataset& dataset = *snapshot.dataset;
  const std::string& id = snapshot.pairs.at(index).id;
  const PairEntry* entry = nullptr;
  for (const PairEntry& candidate : dataset.pairs)
    if (candidate.id == id) entry = &candidate;
  if (entry == nullptr) {
    *why = "pair " + id + " is not in " + dataset.manifest.string();
    return std::nullopt;
  }
  auto inputs = LoadPairInputs(dataset, *entry, why);
  if (!inputs) return std::nullopt;
  OutcomePair pair;
  pair.cloud = std::make_shared<const LidarCloud>(std::move(inputs->cloud));
  pair.image = std::make_shared<const ImageU8>(std::move(inputs->image));
  if (snapshot.view.camera_image == CameraImageMode::kUndistorted && undistorter != nullptr)
    pair.undistorted = std::make_shared<const UndistortedView>(undistorter->Apply(*pair.image));
  ReprojectOutcomePair(snapshot, index, &pair);
  return pair;
}

void ReprojectOutcomePair(const Snapshot& snapshot, int index, OutcomePair* pair) {
  if (!snapshot.solver.result || !pair->cloud) return;
  pair->reprojection =
      ReprojectPair(snapshot.dataset->camera, snapshot.solver.result->cam_from_lidar, *pair->cloud,
                    snapshot.view, snapshot.pairs.at(index).id);
}

void ShowOutcomePair(Snapshot* snapshot, int index, const OutcomePair& pair) {
  snapshot->selected = index;
  PairView& view = snapshot->pairs.Edit(index);
  view.loaded = true;
  view.cloud = pair.cloud;
  snapshot->selected_image = pair.image;
  snapshot->selected_undistorted = pair.undistorted;
  snapshot->selected_image_pair = view.id;
  snapshot->reprojection = pair.reprojection;
  ++snapshot->generation;
}

RigView RigViewOf(const RigFolder& rig, size_t active) {
  RigView view;
  view.path = rig.folder;
  view.active = static_cast<int>(active);
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    RigCameraView camera;
    camera.name = rig.camera_names[c];
    camera.camera = rig.cameras[c].camera;
    camera.captures = static_cast<int>(rig.cameras[c].pairs.size());
    view.cameras.push_back(std::move(camera));
  }
  return view;
}

void ApplyRigOutcome(const RigOutcome& outcome, bool active_solved, RigView* rig) {
  for (size_t c = 0; c < outcome.camera_names.size() && c < rig->cameras.size(); ++c) {
    RigCameraView& view = rig->cameras[c];
    const CalibrationOutcome& single = outcome.single[c];
    if (static_cast<int>(c) != rig->active || !active_solved) {
      view.single =
          single.solution ? std::make_shared<const SolverResult>(*single.solution) : nullptr;
      view.pairs_used = AcceptedPairs(single);
      view.failure = single.solution ? "" : single.failure;
    }
    view.joint_cam_from_lidar.reset();
    view.single_at_joint.reset();
    if (!outcome.joint) continue;
    view.single_at_joint = single.solution->cam_from_lidar;
    const PoseWithSigmas joint = RigJointPose(outcome, c);
    view.joint_cam_from_lidar = joint.pose;
    view.joint_sigma_t_mm = joint.sigma_t_mm;
    view.joint_sigma_r_deg = joint.sigma_r_deg;
  }
  rig->shared_captures = outcome.shared_captures;
  rig->failure = outcome.joint ? "" : outcome.failure;
  rig->relative = outcome.joint ? RigRelativePoses(outcome) : std::vector<PoseWithSigmas>{};
}

}  // namespace calibench::ui
