// Speed of putting a LiDAR sweep into the camera image: projection, hidden-point removal (Katz et
// al. 2007, qhull through PCL) and the z-buffer, on a simulated OS0-128 sweep (128 x 1024 beams)
// seen by the simulator's 1440x1080 pinhole camera. The labels give the sizes and the visible
// fraction.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/io/cloud_io.h"
#include "core/lidar/cloud.h"
#include "core/reproject/reproject.h"
#include "core/sim/sim.h"

namespace calibench {
namespace {

struct Os0Scene {
  CameraModel camera;
  Pose cam_from_lidar;
  LidarCloud cloud;
};

// One pair of the "demo" preset (OS0-128, A3 board, floor and walls), simulated once.
const Os0Scene& SimulatedOs0() {
  static const Os0Scene scene = [] {
    SimOptions sim = SimPreset("demo");
    sim.num_pairs = 1;
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "calibench_bench" / "reproject_os0";
    std::filesystem::create_directories(dir);
    const Dataset dataset = SimulateDataset(sim, dir);
    return Os0Scene{dataset.camera, *dataset.cam_from_lidar_ground_truth,
                    LoadCloud(dataset.pairs[0].cloud)};
  }();
  return scene;
}

std::string Percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f %%", 100.0 * fraction);
  return text;
}

std::string CameraLabel(const CameraModel& camera) {
  return std::to_string(camera.width) + "x" + std::to_string(camera.height);
}

double VisibleFraction(const std::vector<bool>& visible) {
  if (visible.empty()) return 0.0;
  return static_cast<double>(std::count(visible.begin(), visible.end(), true)) / visible.size();
}

// The pipeline's view: the points in the image, then HPR on those.
void BM_ProjectCloudAndHpr(benchmark::State& state) {
  const Os0Scene& scene = SimulatedOs0();
  std::vector<ProjectedPoint> projected;
  std::vector<bool> visible;
  for (auto _ : state) {
    projected = ProjectCloud(scene.camera, scene.cam_from_lidar, scene.cloud);
    std::vector<Vec3> points_in_cam;
    points_in_cam.reserve(projected.size());
    for (const ProjectedPoint& p : projected) {
      points_in_cam.push_back(scene.cam_from_lidar * scene.cloud.points[p.index].cast<double>());
    }
    visible = HiddenPointRemoval(points_in_cam, HprOptions{});
    benchmark::DoNotOptimize(visible);
  }
  state.SetLabel("os0-128 " + std::to_string(scene.cloud.size()) + " points, " +
                 std::to_string(projected.size()) + " in the " + CameraLabel(scene.camera) +
                 " image, " + Percent(VisibleFraction(visible)) + " of those visible");
}
BENCHMARK(BM_ProjectCloudAndHpr)->Unit(benchmark::kMillisecond);

// HPR alone on the whole sweep (all directions around the camera centre).
void BM_HprWholeSweep(benchmark::State& state) {
  const Os0Scene& scene = SimulatedOs0();
  std::vector<Vec3> points_in_cam;
  for (const Eigen::Vector3f& p : scene.cloud.points) {
    points_in_cam.push_back(scene.cam_from_lidar * p.cast<double>());
  }
  std::vector<bool> visible;
  for (auto _ : state) {
    visible = HiddenPointRemoval(points_in_cam, HprOptions{});
    benchmark::DoNotOptimize(visible);
  }
  state.SetLabel("os0-128 " + std::to_string(points_in_cam.size()) + " points, " +
                 Percent(VisibleFraction(visible)) + " visible");
}
BENCHMARK(BM_HprWholeSweep)->Unit(benchmark::kMillisecond);

void BM_ProjectCloudAndZBuffer(benchmark::State& state) {
  const Os0Scene& scene = SimulatedOs0();
  std::vector<ProjectedPoint> projected;
  std::vector<bool> visible;
  for (auto _ : state) {
    projected = ProjectCloud(scene.camera, scene.cam_from_lidar, scene.cloud);
    visible = ZBufferVisibility(scene.camera, projected, ZBufferOptions{});
    benchmark::DoNotOptimize(visible);
  }
  state.SetLabel("os0-128 " + std::to_string(scene.cloud.size()) + " points, " +
                 std::to_string(projected.size()) + " in the " + CameraLabel(scene.camera) +
                 " image, " + Percent(VisibleFraction(visible)) + " of those visible");
}
BENCHMARK(BM_ProjectCloudAndZBuffer)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace calibench
