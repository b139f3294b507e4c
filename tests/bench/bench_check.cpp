// Speed of the targetless check (core/targetless) on the real ACFR VLP-16 + fisheye set: reading
// and reducing 40 frames to their edges, the whole check (alignment from 7 starts, the model's
// dispersion, the weakest direction's profile), and the live step per frame (one new frame's
// edges, then a refinement from the last estimate).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <optional>

#include "core/base/parallel.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/results/result_file.h"
#include "core/targetless/check.h"
#include "core/targetless/check_input.h"
#include "tests/acfr_manifest.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

std::optional<fs::path> AcfrFolder() {
  const fs::path acfr = fs::path(CALIBENCH_SHARED_DIR_DEFAULT) / "datasets/acfr-vlp16-chessboard";
  if (!fs::is_directory(acfr)) return std::nullopt;
  static const fs::path folder =
      test::WriteAcfrFolder(acfr, fs::temp_directory_path() / "calibench_bench" / "check_acfr");
  return folder;
}

// The authors' reference extrinsic stands for R (no board calibration needed here).
void BM_CheckReadAcfr40Frames(benchmark::State& state) {
  const auto folder = AcfrFolder();
  if (!folder) return state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
  CheckInputOptions input;
  input.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(LoadCheckInput(*folder, CheckOptions{}, input));
  state.SetLabel(std::to_string(state.range(0)) + " threads, 40 frames read and reduced to edges");
}
BENCHMARK(BM_CheckReadAcfr40Frames)->Arg(2)->Unit(benchmark::kSecond)->Iterations(2);

void BM_CheckAcfr40Frames(benchmark::State& state) {
  const auto folder = AcfrFolder();
  if (!folder) return state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
  CheckOptions options;
  options.alignment.threads = static_cast<int>(state.range(0));
  const CheckInput input = LoadCheckInput(*folder, options, CheckInputOptions{});
  const Pose reference = test::AcfrReferenceCamFromLidar();
  for (auto _ : state)
    benchmark::DoNotOptimize(
        CheckCalibration(input.frames, input.camera, reference, Mat6::Zero(), options));
  state.SetLabel(std::to_string(state.range(0)) + " threads, the check on 40 frames' edges");
}
BENCHMARK(BM_CheckAcfr40Frames)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->Iterations(2);

// What `watch` would do per new frame: its edges, then the estimate refined over all frames.
void BM_CheckLiveStepPerFrame(benchmark::State& state) {
  const auto folder = AcfrFolder();
  if (!folder) return state.SkipWithError("../shared/datasets/acfr-vlp16-chessboard not found");
  CheckOptions options;
  options.alignment.threads = 2;
  CheckInput input = LoadCheckInput(*folder, options, CheckInputOptions{});
  const Dataset dataset = LoadDataset(*folder);
  const LidarCloud cloud = LoadCloud(dataset.pairs.back().cloud);
  const ImageU8 image = LoadImage(dataset.pairs.back().image);
  const Pose reference = test::AcfrReferenceCamFromLidar();
  for (auto _ : state) {
    input.frames.push_back(MakeEdgeFrame("new", cloud, image, options));
    benchmark::DoNotOptimize(AlignEdges(input.frames, input.camera, reference, options.alignment,
                                        /*first_radius_px=*/-1.0));
    input.frames.pop_back();
  }
  state.SetLabel("one frame's edges + refinement over 41 frames, 2 threads");
}
BENCHMARK(BM_CheckLiveStepPerFrame)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace calibench
