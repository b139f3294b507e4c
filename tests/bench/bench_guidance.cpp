// Speed of guidance on a ring-less LiDAR (Google Benchmark): a sheet cast through the rays learnt
// from one Livox Avia scan (core/lidar/board_returns.h, LearntRaysNear), and `advise`'s next pose
// over an 8-pair Avia capture. Figures go to the closing note / docs/results.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "core/guidance/advise.h"
#include "core/guidance/next_pose.h"
#include "core/io/cloud_io.h"
#include "core/lidar/board_returns.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/sim.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

// An 8-pair simulated Avia capture (0.5 s frames), made once per process.
const Dataset& AviaCapture() {
  static const Dataset dataset = [] {
    SimOptions sim = SimPreset("default");
    sim.lidar = LidarModel::kAvia;
    sim.lidar_frame_s = 0.5;
    sim.num_pairs = 8;
    sim.seed = 7;
    const fs::path dir = fs::temp_directory_path() / "calibench_bench" / "guidance_avia";
    fs::remove_all(dir);
    return SimulateDataset(sim, dir);
  }();
  return dataset;
}

// An A3 sheet `distance_m` ahead of the LiDAR, turned 30° about its vertical.
LidarRectangle SheetAhead(double distance_m) {
  Mat3 facing;  // x along the sheet's width (LiDAR y), y up (LiDAR z), z towards the LiDAR (−x)
  facing << 0, 0, -1, 1, 0, 0, 0, 1, 0;
  LidarRectangle sheet;
  sheet.lidar_from_rectangle = Pose::Identity();
  sheet.lidar_from_rectangle.linear() =
      Eigen::AngleAxisd(30.0 * M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix() * facing;
  sheet.lidar_from_rectangle.translation() = Vec3(distance_m, 0.2, 0.0);
  sheet.half_size_m = Vec2(0.21, 0.297);
  return sheet;
}

// One candidate pose's predicted returns: arg = the sheet's distance in decimetres.
void BM_CastSheetLearntAviaRays(benchmark::State& state) {
  const LidarCloud cloud = LoadCloud(AviaCapture().pairs[0].cloud);
  const BeamTable learnt = LearnBeamTable({&cloud});
  const LidarRectangle sheet = SheetAhead(state.range(0) / 10.0);
  size_t returns = 0;
  for (auto _ : state) {
    const BoardReturns cast = CastBoardReturns(learnt, sheet);
    returns = cast.points.size();
    benchmark::DoNotOptimize(returns);
  }
  state.counters["rays"] = static_cast<double>(learnt.rays->size());
  state.counters["returns"] = static_cast<double>(returns);
}
BENCHMARK(BM_CastSheetLearntAviaRays)->Arg(15)->Arg(40)->Unit(benchmark::kMicrosecond);

// `advise` with a goal the 8 pairs do not meet: the calibration, then the next pose searched.
void BM_AdviseNextPoseAvia8Pairs(benchmark::State& state) {
  const Dataset& dataset = AviaCapture();
  AdviseOptions options;
  options.goal.translation_mm = 0.2;
  options.goal.rotation_deg = 0.005;
  const CalibrationOutcome outcome = CalibrateDataset(dataset, options.pipeline);
  std::string failure;
  for (auto _ : state) {
    const CaptureAdvice advice = AdviseCapture(dataset, outcome, options);
    failure = advice.next ? "" : "no next pose: " + advice.next_failure;
    benchmark::DoNotOptimize(failure);
  }
  if (!failure.empty()) state.SkipWithError(failure.c_str());
}
BENCHMARK(BM_AdviseNextPoseAvia8Pairs)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace calibench
