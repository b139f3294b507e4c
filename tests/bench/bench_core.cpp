// Speed of the pipeline's stages (Google Benchmark). Figures go to the closing note /
// docs/results.md.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <random>

#include "core/base/allocator.h"
#include "core/base/image.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/io/rig_folder.h"
#include "core/lidar/cloud.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/rig.h"
#include "core/lidar_camera/solver.h"
#include "core/lrf/depth_planes.h"
#include "core/lrf/scan_lines.h"
#include "core/lrf/solver.h"
#include "core/session/calibration_job.h"
#include "core/sim/lrf_sim.h"
#include "core/sim/sim.h"
#include "core/sim/sim_wave.h"
#include "core/target/board_camera.h"
#include "core/target/lidar_board_detect.h"
#include "core/target/lidar_plane.h"
#include "tests/acfr_manifest.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

fs::path BenchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "calibench_bench" / name;
  fs::create_directories(dir);
  return dir;
}

std::optional<fs::path> AcfrDir() {
  const fs::path dir = fs::path(CALIBENCH_SHARED_DIR_DEFAULT) / "datasets/acfr-vlp16-chessboard";
  if (fs::is_directory(dir)) return dir;
  return std::nullopt;
}

void BM_GaussNewton40Pairs(benchmark::State& state) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal(0, 1);
  const Pose truth = ExpSE3((Vec6() << 0.05, -0.1, 0.08, 1.2, -1.2, 1.2).finished());
  std::vector<PlanePair> pairs;
  for (int i = 0; i < 40; ++i) {
    const Vec3 n = (Vec3(0, 0, -1) + 0.4 * Vec3(normal(rng), normal(rng), 0)).normalized();
    const Plane cam{n, 2.0 + std::abs(normal(rng))};
    Plane lidar = TransformPlane(truth.inverse(), cam);
    lidar.distance += 0.005 * normal(rng);
    PlanePair pair{std::to_string(i), lidar, cam};
    // Covariances of the size the features carry (normal 3 mrad, distance 5 mm LiDAR; a tenth of
    // that for the camera), so that the weighted method whitens as it does on real pairs.
    pair.lidar_covariance.diagonal() << 9e-6, 9e-6, 9e-6, 2.5e-5;
    pair.camera_covariance = 0.01 * pair.lidar_covariance;
    pairs.push_back(pair);
  }
  SolverOptions options;
  options.method = static_cast<SolverMethod>(state.range(0));
  state.SetLabel(SolverMethodName(options.method));
  std::string why;
  for (auto _ : state) {
    const Pose guess = *InitialGuessFromPlanes(pairs, &why);
    benchmark::DoNotOptimize(PlaneAlignmentSolver(pairs, options, guess).Run());
  }
}
BENCHMARK(BM_GaussNewton40Pairs)
    ->Arg(static_cast<int>(SolverMethod::kCa2libGn))
    ->Arg(static_cast<int>(SolverMethod::kWeightedMl))
    ->Unit(benchmark::kMicrosecond);

// One simulated pair per LiDAR model, made once.
const Dataset& SimulatedPair(LidarModel lidar) {
  static std::map<LidarModel, Dataset> cache;
  auto it = cache.find(lidar);
  if (it != cache.end()) return it->second;
  SimOptions sim = SimPreset("default");
  sim.lidar = lidar;
  sim.num_pairs = 1;
  return cache[lidar] = SimulateDataset(sim, BenchDir("pair_" + LidarModelName(lidar)));
}

// The solve of 15 ring-less pairs (a nodding scanner's board-only crops) with the LiDAR model
// chosen by the held-out pairs (Arg 1: two candidates x 5 folds solved first) and without (Arg 0).
void BM_SolveWithLidarModelEvidence(benchmark::State& state) {
  static const std::vector<PairFeatures> features = [] {
    SimOptions sim = SimPreset("default");
    sim.lidar = LidarModel::kNodding2d;
    sim.num_pairs = 15;
    sim.min_distance_m = 0.9;
    sim.max_distance_m = 1.4;
    sim.lidar_range_noise_m = 0.01;
    sim.board_only_clouds = true;
    const Dataset dataset = SimulateDataset(sim, BenchDir("model_evidence"));
    std::vector<PairFeatures> pairs;
    for (const PairEntry& pair : dataset.pairs)
      pairs.push_back(ExtractPairFeatures(dataset, pair, PipelineOptions{}));
    return pairs;
  }();
  PipelineOptions options;
  options.lidar_model_evidence.enabled = state.range(0) != 0;
  state.SetLabel(options.lidar_model_evidence.enabled ? "evidence" : "the look's model");
  for (auto _ : state) benchmark::DoNotOptimize(SolveFromFeatures(features, options));
}
BENCHMARK(BM_SolveWithLidarModelEvidence)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_LidarPlaneExtraction(benchmark::State& state) {
  const Dataset& dataset = SimulatedPair(static_cast<LidarModel>(state.range(0)));
  const LidarCloud cloud = LoadCloud(dataset.pairs[0].cloud);
  state.SetLabel(LidarModelName(static_cast<LidarModel>(state.range(0))) + ", " +
                 std::to_string(cloud.size()) + " points");
  std::string why;
  for (auto _ : state) {
    const auto region = SelectSeedRegion(cloud, *dataset.pairs[0].lidar_seed);
    benchmark::DoNotOptimize(FitBoardPlane(cloud, region, LidarPlaneOptions{}, &why));
  }
}
BENCHMARK(BM_LidarPlaneExtraction)
    ->Arg(static_cast<int>(LidarModel::kVlp16))
    ->Arg(static_cast<int>(LidarModel::kOs0_128))
    ->Unit(benchmark::kMillisecond);

// The board found without a seed in one cloud (one core): a real VLP-16 scan, a simulated
// OS0-128 scan, and a ring-less swept copy of it.
void BM_LidarBoardDetection(benchmark::State& state) {
  LidarCloud cloud;
  BoardSpec board = BoardPreset("a3");
  std::string label;
  if (state.range(0) == 0) {
    const auto dir = AcfrDir();
    if (!dir) {
      state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
      return;
    }
    cloud = LoadCloud(*dir / "pcd/pose20_full.pcd");
    board.cols = 5;
    board.rows = 7;
    board.square_size = 0.095;
    board.board_width = 0.61;
    board.board_height = 0.85;
    label = "real VLP-16";
  } else {
    const Dataset& dataset = SimulatedPair(LidarModel::kOs0_128);
    cloud = LoadCloud(dataset.pairs[0].cloud);
    label = "OS0-128";
    if (state.range(0) == 2) {  // scatter the rings: each return turned by up to 0.35 deg
      std::mt19937_64 rng(4);
      std::uniform_real_distribution<float> jitter(-0.35f * M_PI / 180, 0.35f * M_PI / 180);
      for (Eigen::Vector3f& p : cloud.points)
        p = Eigen::AngleAxisf(jitter(rng), Eigen::Vector3f(p.y(), -p.x(), 0).normalized()) * p;
      cloud.ring.clear();
      label = "swept, ring-less";
    }
  }
  state.SetLabel(label + ", " + std::to_string(cloud.size()) + " points");
  for (auto _ : state)
    benchmark::DoNotOptimize(DetectLidarBoard(cloud, board, LidarBoardDetectionOptions{}));
}
BENCHMARK(BM_LidarBoardDetection)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// Reading one real VLP-16 cloud (ASCII PCD, 0.9 MB, 24k points) and one real 1920 x 1208 PNG
// (1.4 MB): the per-pair file cost, in bytes of file per second.
template <typename Load>
void LoadRealFile(benchmark::State& state, const char* relative_path, Load load) {
  const auto dir = AcfrDir();
  if (!dir) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  const fs::path path = *dir / relative_path;
  for (auto _ : state) benchmark::DoNotOptimize(load(path));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(fs::file_size(path)));
}
void BM_LoadAsciiPcdReal(benchmark::State& state) {
  LoadRealFile(state, "pcd/pose20_full.pcd", [](const fs::path& p) { return LoadCloud(p); });
}
BENCHMARK(BM_LoadAsciiPcdReal)->Unit(benchmark::kMillisecond);
void BM_LoadPngReal1920x1208(benchmark::State& state) {
  LoadRealFile(state, "images/pose20.png", [](const fs::path& p) { return LoadImage(p); });
}
BENCHMARK(BM_LoadPngReal1920x1208)->Unit(benchmark::kMillisecond);

// The dataset-level steps for the 40 real pairs: the background model over every cloud, and the
// whole calibration without seeds (detection and camera-guided completion included), 2 threads.
void BM_BackgroundModelReal40Clouds(benchmark::State& state) {
  const auto dir = AcfrDir();
  if (!dir) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  std::vector<LidarCloud> clouds;
  for (int n = 1; n <= 40; ++n)
    clouds.push_back(LoadCloud(*dir / ("pcd/pose" + std::to_string(n) + "_full.pcd")));
  for (auto _ : state) {
    SceneBackground background;
    for (const LidarCloud& cloud : clouds) background.Add(cloud);
    std::string why;
    benchmark::DoNotOptimize(background.Finish(&why));
  }
}
BENCHMARK(BM_BackgroundModelReal40Clouds)->Unit(benchmark::kMillisecond);

void BM_CalibrateReal40PairsWithoutSeeds2Threads(benchmark::State& state) {
  const auto dir = AcfrDir();
  if (!dir) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  Dataset dataset = LoadDataset(test::WriteAcfrManifest(*dir, BenchDir("acfr")));
  for (PairEntry& pair : dataset.pairs) pair.lidar_seed.reset();
  PipelineOptions options;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(CalibrateDataset(dataset, options));
}
BENCHMARK(BM_CalibrateReal40PairsWithoutSeeds2Threads)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

void BM_BoardDetectionAndPnp1920x1208(benchmark::State& state) {
  const auto dir = AcfrDir();
  if (!dir) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  const fs::path manifest = test::WriteAcfrManifest(*dir, BenchDir("acfr"));
  const Dataset dataset = LoadDataset(manifest);
  const ImageU8 image = LoadImage(dataset.pairs[15].image);
  std::string why;
  for (auto _ : state) {
    const auto detection = DetectBoard(image, dataset.target, BoardDetectionOptions{}, &why);
    if (!detection) {
      state.SkipWithError(why.c_str());
      return;
    }
    benchmark::DoNotOptimize(EstimateBoardPose(dataset.camera, *detection, PnpOptions{}, &why));
  }
}
BENCHMARK(BM_BoardDetectionAndPnp1920x1208)->Unit(benchmark::kMillisecond);

void BM_CalibrateReal40Pairs2Threads(benchmark::State& state) {
  const auto dir = AcfrDir();
  if (!dir) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  const Dataset dataset = LoadDataset(test::WriteAcfrManifest(*dir, BenchDir("acfr")));
  PipelineOptions options;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(CalibrateDataset(dataset, options));
}
BENCHMARK(BM_CalibrateReal40Pairs2Threads)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

// A waved board's recording (core/sim/sim_wave.h: `state.range(0)` seconds at 0.45 m/s, a VLP-16
// and a 1440 x 1080 camera at 10 Hz, its stamps 40 ms late): `calibrate` of its folder, every
// sweep that sees the board a pair with its frames, the offset searched. The label says the
// calibration's time per second recorded (below 1: faster than the capture).
void BM_CalibrateWavedBoard2Threads(benchmark::State& state) {
  WaveOptions wave;
  wave.rig.lidar_range_noise_m = 0.01;
  wave.duration_s = static_cast<double>(state.range(0));
  const WavedDataset waved = SimulateWavedDataset(wave, BenchDir("waved"));
  PipelineOptions options;
  options.threads = 2;
  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(CalibrateDataset(waved.dataset, options));
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  state.SetLabel(std::to_string(waved.dataset.pairs.size()) + " pairs, " +
                 std::to_string(seconds / wave.duration_s).substr(0, 4) + " s per second recorded");
}
BENCHMARK(BM_CalibrateWavedBoard2Threads)
    ->Arg(10)
    ->Arg(40)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// The real ACFR capture as a rig of two cameras (cam0: all 40 frames, cam1: every other one;
// links, not copies): `calibrate --dataset <rig>`, each camera's own calibration and the rig
// solve. Against BM_CalibrateReal40Pairs2Threads: what the second camera and the rig add.
void BM_CalibrateRealRigTwoCameras2Threads(benchmark::State& state) {
  const auto acfr = AcfrDir();
  if (!acfr) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  const fs::path folder = test::WriteAcfrFolder(*acfr, BenchDir("rig_source"));
  const fs::path rig = BenchDir("rig");
  fs::remove_all(rig);
  fs::create_directories(rig / "cameras");
  fs::copy(folder / "target.json", rig / "target.json");
  fs::create_directory_symlink(fs::absolute(folder / "clouds"), rig / "clouds");
  const Dataset all = LoadDataset(folder);
  for (int c = 0; c < 2; ++c) {
    const std::string name = "cam" + std::to_string(c);
    fs::copy(folder / "camera.yaml", rig / "cameras" / (name + ".yaml"));
    fs::create_directories(rig / "images" / name);
    for (size_t i = c; i < all.pairs.size(); i += c + 1)
      fs::create_symlink(fs::absolute(all.pairs[i].image),
                         rig / "images" / name / all.pairs[i].image.filename());
  }
  const RigFolder loaded = LoadRig(rig);
  PipelineOptions options;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(CalibrateRig(loaded, options));
  state.SetLabel("40 + 20 pairs, 20 captures shared");
}
BENCHMARK(BM_CalibrateRealRigTwoCameras2Threads)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

// `watch`'s step for one new pair (core/session/calibration_job.h): the real ACFR capture's first
// state.range(0) - 1 pairs already in the job, then the next pair read, detected, solved with the
// others from the last solution, checked and advised. The job is copied outside the timing.
void BM_WatchIncrementalStep(benchmark::State& state) {
  const auto acfr = AcfrDir();
  if (!acfr) {
    state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
    return;
  }
  const fs::path folder = test::WriteAcfrFolder(*acfr, BenchDir("watch_step"));
  Dataset all = LoadDataset(folder);
  const int before = static_cast<int>(state.range(0)) - 1;
  Dataset setup = all;
  setup.pairs.clear();
  CalibrationJobOptions options;
  options.warm_start = true;  // as `watch` runs it
  CalibrationJob prepared(setup, options);
  for (int i = 0; i < before; ++i) prepared.AddPair(all.pairs[i]);
  prepared.Solve();
  for (auto _ : state) {
    state.PauseTiming();
    CalibrationJob job = prepared;
    state.ResumeTiming();
    job.AddPair(all.pairs[before]);
    job.Solve();
    benchmark::DoNotOptimize(job.Advise());
  }
  state.SetLabel("pair " + std::to_string(before + 1) + " of a real VLP-16 + 1920x1208 capture");
}
BENCHMARK(BM_WatchIncrementalStep)->Arg(10)->Arg(40)->Unit(benchmark::kMillisecond)->Iterations(3);

// One simulated three-face observation (R2000 scan, 1280x720 ZED-like depth).
const LrfSimObservation& LrfObservationForBench() {
  static const LrfSimObservation observation = [] {
    LrfSimOptions options = *LrfSimPreset("paper");
    options.observations = 1;
    return RenderLrfObservation(options, SampleTargetPoses(options).front(), 1);
  }();
  return observation;
}

void BM_LrfScanFeatures(benchmark::State& state) {
  const LrfSimObservation& o = LrfObservationForBench();
  for (auto _ : state)
    benchmark::DoNotOptimize(ExtractScanFeatures(o.scan, ThreeFaceTarget{}, ScanFeatureOptions{}));
}
BENCHMARK(BM_LrfScanFeatures)->Unit(benchmark::kMillisecond);

// Arguments: normals (0 ours, 1 PCL's integral image), plane search (0 ours, 1 PCL's SAC).
void BM_LrfDepthFeatures1280x720(benchmark::State& state) {
  const LrfSimObservation& o = LrfObservationForBench();
  DepthFeatureOptions options;
  options.normals =
      state.range(0) ? DepthNormalMethod::kPclIntegralImage : DepthNormalMethod::kGridPca;
  options.plane_search =
      state.range(1) ? DepthPlaneSearch::kPclSacNormalPlane : DepthPlaneSearch::kPointNormalRansac;
  for (auto _ : state)
    benchmark::DoNotOptimize(ExtractDepthFeatures(o.depth, ThreeFaceTarget{}, options));
}
BENCHMARK(BM_LrfDepthFeatures1280x720)
    ->ArgNames({"pcl_normals", "pcl_sac"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

void BM_LrfRefinedSolve10Observations(benchmark::State& state) {
  LrfSimOptions options = *LrfSimPreset("paper");
  options.observations = 12;
  std::vector<LrfObservation> observations;
  for (const Pose& pose : SampleTargetPoses(options)) {
    const LrfSimObservation o = RenderLrfObservation(options, pose, observations.size() + 7);
    LrfObservation f;
    f.scan = ExtractScanFeatures(o.scan, options.target, ScanFeatureOptions{});
    f.depth = ExtractDepthFeatures(o.depth, options.target, DepthFeatureOptions{});
    if (f.scan.ok && f.depth.ok) observations.push_back(f);
    if (observations.size() == 10) break;
  }
  for (auto _ : state) benchmark::DoNotOptimize(SolveLrf(observations, LrfSolverOptions{}));
}
BENCHMARK(BM_LrfRefinedSolve10Observations)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace calibench

// As calibench's own main() does (core/base/allocator.h), so that the figures are the tool's.
int main(int argc, char** argv) {
  calibench::KeepFreedMemoryForReuse();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
