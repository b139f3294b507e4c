// Workbench costs on llvmpipe: a full frame at 1600x900 with a 131k-point OS0-128 cloud and a
// 1440x1080 image, and the memory a 40-pair session holds.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <thread>

#include "core/base/allocator.h"
#include "core/sim/sim.h"
#include "tests/acfr_manifest.h"
#include "ui/gfx/context.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/gl_api.h"
#include "ui/gfx/renderers.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/imgui_host.h"

namespace calibench {
namespace {

// Resident memory now (kB), from /proc/self/status.
long ResidentKb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  long value = 0;
  while (status >> key) {
    if (key == "VmRSS:") {
      status >> value;
      return value;
    }
    status.ignore(1 << 10, '\n');
  }
  return 0;
}

std::filesystem::path SimulatedDemo(int pairs) {
  const auto dir = std::filesystem::temp_directory_path() / "calibench_bench" /
                   ("ui_demo_" + std::to_string(pairs));
  if (!std::filesystem::exists(dir / "dataset.json")) {
    SimOptions sim = SimPreset("demo");  // OS0-128 (131072 beams), 1440x1080 pinhole camera
    sim.num_pairs = pairs;
    SimulateDataset(sim, dir);
  }
  return dir / "dataset.json";
}

// A headless GL context (nullptr after marking the benchmark skipped) and the 3-pair demo opened
// and solved in `controller`, so that the camera view shows the reprojection with hidden-point
// removal.
std::unique_ptr<gfx::GlContext> SolvedDemo(benchmark::State& state, ui::Controller* controller,
                                           const char* session_name) {
  std::string why;
  auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &why);
  if (!context) {
    state.SkipWithError(why.c_str());
    return nullptr;
  }
  controller->OpenDataset(SimulatedDemo(3), std::filesystem::temp_directory_path() / session_name);
  controller->WaitIdle();
  controller->Apply(ui::RunSolver{});
  controller->WaitIdle();
  return context;
}

void BM_WorkbenchFrame1600x900(benchmark::State& state) {
  ui::Controller controller;
  const auto context = SolvedDemo(state, &controller, "bench_ui.json");
  if (!context) return;
  ui::ImGuiHost host(nullptr);
  ui::Workbench workbench;
  const ui::Snapshot snapshot = controller.GetSnapshot();
  state.SetLabel(std::to_string(snapshot.pairs[0].cloud->size()) + " points, " +
                 std::to_string(snapshot.reprojection ? snapshot.reprojection->points.size() : 0) +
                 " reprojected; " + context->Description());
  ui::RenderWorkbenchHeadless(controller, workbench, host, ui::Layout::kWorkbench, 1600, 900, 2);
  for (auto _ : state)
    benchmark::DoNotOptimize(ui::RenderWorkbenchHeadless(controller, workbench, host,
                                                         ui::Layout::kWorkbench, 1600, 900, 1));
}
BENCHMARK(BM_WorkbenchFrame1600x900)->Unit(benchmark::kMillisecond)->UseRealTime();

// One frame after an edit, drawn into the window's offscreen framebuffer and finished (glFinish),
// without the headless readback: /0 the 3D view turned (an orbit drag: the 3D view redraws),
// /1 the reprojected points' opacity changed (a slider: the camera view redraws), /2 a pair
// rejected (the list changes; no view redraws). Second argument: 1 repaints only the regions that
// changed (the window's way), 0 the whole frame (as before regions; the comparison). Third
// argument: 1 points drawn as PointRenderer chooses (the software splat on llvmpipe), 0 always
// GL_POINTS (as before the splat; the comparison).
void BM_WorkbenchFrameAfterEdit1600x900(benchmark::State& state) {
  ui::Controller controller;
  const auto context = SolvedDemo(state, &controller, "bench_ui_edit.json");
  if (!context) return;
  ui::ImGuiHost host(nullptr);
  host.set_repaint_only_changes(state.range(1) != 0);
  if (state.range(2) == 0) gfx::SetPointDrawingForNewRenderers(gfx::PointDrawing::kGlPoints);
  ui::Workbench workbench;
  ui::RenderWorkbenchHeadless(controller, workbench, host, ui::Layout::kWorkbench, 1600, 900, 3);
  gfx::Framebuffer target;
  int edit = 0;
  for (auto _ : state) {
    state.PauseTiming();
    ui::ViewState view = controller.GetSnapshot().view;
    ++edit;
    if (state.range(0) == 0) {
      view.orbit_yaw_rad += 0.05;
      controller.Apply(ui::SetView{view});
    } else if (state.range(0) == 1) {
      view.point_opacity = edit % 2 ? 0.9 : 1.0;
      controller.Apply(ui::SetView{view});
    } else {
      controller.Apply(
          ui::SetPairStatus{2, edit % 2 ? PairStatus::kRejected : PairStatus::kAccepted});
    }
    controller.WaitIdle();
    state.ResumeTiming();
    host.DrawFrame(target, 1600, 900, 1.0 / 60.0, [&] {
      for (const auto& intent :
           workbench.Frame(controller.GetSnapshot(), 1600, 900, ui::Layout::kWorkbench, 1.0 / 60.0))
        controller.Apply(intent);
    });
    glFinish();
  }
  gfx::SetPointDrawingForNewRenderers(std::nullopt);
  state.SetLabel(context->Description());
}
BENCHMARK(BM_WorkbenchFrameAfterEdit1600x900)
    ->ArgsProduct({{0, 1, 2}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The real 40-pair VLP-16 + fisheye set's manifest, written into a work folder `name` (nullopt
// after marking the benchmark skipped where ../shared is absent).
std::optional<std::filesystem::path> RealAcfr40(benchmark::State& state, const char* name,
                                                std::filesystem::path* work) {
  const char* env = std::getenv("CALIBENCH_SHARED_DIR");
  const std::filesystem::path shared = env ? env : CALIBENCH_SHARED_DIR_DEFAULT;
  const auto dir = shared / "datasets/acfr-vlp16-chessboard";
  if (!std::filesystem::exists(dir)) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return std::nullopt;
  }
  *work = std::filesystem::temp_directory_path() / "calibench_bench" / name;
  std::filesystem::create_directories(*work);
  return test::WriteAcfrManifest(dir, *work);
}

// Opening the real 40-pair VLP-16 + fisheye set in the workbench: how long until the selected
// pair is on screen (its cloud, its LiDAR plane and its camera image), and until every pair has
// loaded behind it.
void BM_WorkbenchFirstPairReal40(benchmark::State& state) {
  std::filesystem::path work;
  const auto found = RealAcfr40(state, "first_pair", &work);
  if (!found) return;
  const std::filesystem::path manifest = *found;
  double first_s = 0, all_s = 0;
  for (auto _ : state) {
    std::filesystem::remove(work / "first_pair.session.json");
    const auto start = std::chrono::steady_clock::now();
    ui::Controller controller;
    controller.OpenDataset(manifest, work / "first_pair.session.json");
    auto since = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    while (true) {
      const ui::Snapshot s = controller.GetSnapshot();
      if (s.selected >= 0 && s.pairs[s.selected].cloud && s.pairs[s.selected].lidar &&
          s.selected_image)
        break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    first_s = since();
    controller.WaitIdle();
    all_s = since();
  }
  state.counters["first_pair_s"] = first_s;
  state.counters["all_pairs_s"] = all_s;
}
BENCHMARK(BM_WorkbenchFirstPairReal40)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// What a panel frame pays to read the state: one GetSnapshot of the real 40-pair VLP-16 + fisheye
// set, loaded, detected and solved (the window takes one per frame).
void BM_SnapshotReal40(benchmark::State& state) {
  std::filesystem::path work;
  const auto manifest = RealAcfr40(state, "snapshot", &work);
  if (!manifest) return;
  std::filesystem::remove(work / "snapshot.session.json");
  ui::Controller controller;
  controller.OpenDataset(*manifest, work / "snapshot.session.json");
  controller.WaitIdle();
  controller.Apply(ui::RunSolver{});
  controller.WaitIdle();
  for (auto _ : state) benchmark::DoNotOptimize(controller.GetSnapshot());
  state.counters["pairs"] = static_cast<double>(controller.GetSnapshot().pairs.size());
}
BENCHMARK(BM_SnapshotReal40)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_Session40PairsMemory(benchmark::State& state) {
  ReleaseFreedMemory();  // what earlier benchmarks left
  const auto manifest = SimulatedDemo(40);
  for (auto _ : state) {
    const long before = ResidentKb();
    ui::Controller controller;
    controller.OpenDataset(manifest, std::filesystem::temp_directory_path() / "bench_ui40.json");
    controller.WaitIdle();
    state.counters["rss_MiB"] = (ResidentKb() - before) / 1024.0;
    state.counters["points_per_pair"] =
        static_cast<double>(controller.GetSnapshot().pairs[0].cloud->size());
  }
}
BENCHMARK(BM_Session40PairsMemory)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// Points alone, as the 3D view draws them: n points in front of the camera, all inside a
// 530 x 420 view (the 3D view's size at 1600 x 900), 2 px round, opaque. Second argument: 0
// GL_POINTS, 1 the software splat that PointRenderer picks on llvmpipe.
void BM_PointsInView530x420(benchmark::State& state) {
  std::string why;
  const auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &why);
  if (!context) return state.SkipWithError(why.c_str());
  const auto n = static_cast<size_t>(state.range(0));
  std::mt19937 random(1);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> positions(n);
  for (auto& p : positions) p = {uniform(random), uniform(random), -3.0f + uniform(random)};
  gfx::PointRenderer points;
  points.set_drawing(state.range(1) ? gfx::PointDrawing::kSoftwareSplat
                                    : gfx::PointDrawing::kGlPoints);
  points.Upload(positions, std::vector<gfx::Rgba>(n, gfx::Rgba{200, 100, 50, 255}));
  gfx::Framebuffer target;
  target.Resize(530, 420);
  const gfx::Matrix4f view_projection = gfx::Perspective(1.0f, 530.0f / 420.0f, 0.1f, 100.0f);
  for (auto _ : state) {
    target.Clear(0, 0, 0, 1);
    points.Draw(view_projection, 2.0f);
    glFinish();
  }
  state.SetLabel(context->Description());
}
BENCHMARK(BM_PointsInView530x420)
    ->ArgsProduct({{31000, 131000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace calibench
