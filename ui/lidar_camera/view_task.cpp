// What the views show of the selected pair, a task of the controller: selection, image,
// reprojection, the view's settings recorded (ui/lidar_camera/view_task.h).
#include "ui/lidar_camera/view_task.h"

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "core/camera/undistort.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {
namespace {

// Where the 3D view should look for `pair`, and how well that is known (ViewTask::Framed).
struct Framing {
  std::array<double, 3> center{};
  double radius_m = 0;
  int quality = 0;
};

// The board's inliers (about them, with 1.5 m of the scene around a small board) once its plane
// is fitted; else the cloud's bulk: about its per-axis median, as far as half its points lie.
std::optional<Framing> FramingOf(const PairView& pair) {
  if (!pair.cloud || pair.cloud->points.empty()) return std::nullopt;
  const auto& points = pair.cloud->points;
  Framing framing;
  if (pair.lidar && !pair.lidar->inliers.empty()) {
    const Vec3 c = pair.lidar->inlier_centroid;
    double board_radius = 0;
    for (int i : pair.lidar->inliers)
      board_radius = std::max(board_radius, (points[i].cast<double>() - c).norm());
    framing = {{c.x(), c.y(), c.z()}, std::max(1.5, 2.5 * board_radius), 2};
    return framing;
  }
  std::vector<double> axis[3];
  for (const auto& p : points)
    if (p.allFinite())
      for (int a = 0; a < 3; ++a) axis[a].push_back(p[a]);
  if (axis[0].empty()) return std::nullopt;
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  for (int a = 0; a < 3; ++a) framing.center[a] = median(axis[a]);
  const Vec3 c(framing.center[0], framing.center[1], framing.center[2]);
  std::vector<double> distances;
  for (const auto& p : points)
    if (p.allFinite()) distances.push_back((p.cast<double>() - c).norm());
  framing.radius_m = std::clamp(median(distances), 1.0, 30.0);
  framing.quality = 1;
  return framing;
}

// The orbit's fields alike: the view not turned, panned or zoomed since.
bool SameOrbit(const ViewState& a, const ViewState& b) {
  return a.orbit_target == b.orbit_target && a.orbit_yaw_rad == b.orbit_yaw_rad &&
         a.orbit_pitch_rad == b.orbit_pitch_rad && a.orbit_distance_m == b.orbit_distance_m;
}

}  // namespace

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
  Frame(/*forced=*/false);
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

void ViewTask::Frame(bool forced) {
  host_.mutex.AssertHeld(__func__);
  Snapshot& state = host_.state;
  if (!state.HasPair(state.selected)) return;
  const PairView& pair = state.pairs.at(state.selected);
  // What it could be framed on now (FramingOf's quality), known without reading the cloud.
  const int available = pair.lidar && !pair.lidar->inliers.empty() ? 2 : pair.cloud ? 1 : 0;
  if (!forced && framed_.pair_id == pair.id && available <= framed_.quality) return;
  const std::optional<Framing> framing = FramingOf(pair);
  if (!framing) return;
  if (!forced && framed_.pair_id == pair.id &&
      (framing->quality <= framed_.quality || !SameOrbit(state.view, framed_.view)))
    return;
  state.view = FramedOn(state.view, framing->center, framing->radius_m);
  framed_ = {pair.id, framing->quality, state.view};
  ++state.generation;
}

void ViewTask::Restored() {
  host_.mutex.AssertHeld(__func__);
  const Snapshot& state = host_.state;
  if (!state.HasPair(state.selected) || SameOrbit(state.view, ViewState{}))
    framed_ = {};
  else
    framed_ = {state.pairs.at(state.selected).id, 2, state.view};
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
