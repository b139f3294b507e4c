// Import against the capture it reads: a simulated on-site recording (tests/sim_recording.h: a
// VLP-16 at 10 Hz, a 1280 x 720 bgr8 camera at 15 Hz, the A3 board held 6 s at each of N poses
// and carried 2 s between them; about 0.4 GB per pose) written once into build/bench_bags/ as a
// ROS 2 MCAP (lz4) and a ROS 1 bag (lz4), then imported.
//   BM_ImportSimRecording/N/format  the import as a whole; counters: the recording's length, the
//                                   import's wall and CPU time, their ratio, pairs, searches
//   BM_ImportPeakMemory/N/format    `calibench import` as a user runs it, in a process of its
//                                   own: its peak resident memory (wait4's ru_maxrss); 19 poses
//                                   make a 3.5 GB MCAP (lz4), the size of the real recording issue
//                                   51 measured
// And what import pays per message, to see where the time goes:
//   BM_ImportSweep      a VLP-16 sweep decoded, gridded and compared with its hold's first
//   BM_ImportImageStamp an image's stamp read (every image pays only this)
//   BM_ImportTry        a try: the board searched in one image, followed into 5 others, 6 PnP
//   BM_ImportSearchEveryImage  what the importer before the LiDAR-first rule paid per image
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <map>

#include "core/capture/bag_import.h"
#include "core/lidar/cloud_motion.h"
#include "core/recording/ros_messages.h"
#include "core/target/board_camera.h"
#include "tests/sim_recording.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

const char* kRecordingFormats[] = {"mcap", "bag"};

struct BenchRecording {
  fs::path path;
  test::SimRecordingTruth truth;
};

// Written on first use; a second run of the benchmark reuses the file (and its truth, which is
// deterministic for the options).
const BenchRecording& Recording(int poses, int format) {
  static std::map<std::pair<int, int>, BenchRecording> recordings;
  auto& recording = recordings[{poses, format}];
  if (!recording.path.empty()) return recording;
  const fs::path folder = fs::absolute("bench_bags");
  fs::create_directories(folder);
  recording.path = folder / ("capture" + std::to_string(poses) + "." + kRecordingFormats[format]);
  test::SimRecordingOptions options;
  options.poses = poses;
  recording.truth = test::PlanSimRecording(options);
  if (fs::exists(recording.path)) return recording;
  const bool bag = format == 1;
  const fs::path partial = recording.path.string() + ".part";
  auto writer = bag ? test::OpenRos1BagWriter(partial, "lz4")
                    : test::OpenMcapWriter(partial, "ros2", "lz4", true);
  test::WriteSimRecording(writer.get(), bag ? MessageEncoding::kRos1 : MessageEncoding::kCdr,
                          options);
  writer->Close();
  fs::rename(partial, recording.path);
  return recording;
}

void BM_ImportSimRecording(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const int format = static_cast<int>(state.range(1));
  const BenchRecording& recording = Recording(poses, format);
  const fs::path out = recording.path.string() + ".dataset";
  BagImportSummary summary;
  double wall = 0.0, cpu = 0.0;
  for (auto _ : state) {
    fs::remove_all(out);
    const double cpu_start = CpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    summary = ImportBag(recording.path, out, recording.truth.board, {});
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cpu = CpuSeconds() - cpu_start;
  }
  state.counters["recording_s"] = recording.truth.seconds;
  state.counters["import_s"] = wall;
  state.counters["cpu_s"] = cpu;
  state.counters["x_capture"] = wall / recording.truth.seconds;
  state.counters["pairs"] = static_cast<double>(summary.pair_ids.size());
  state.counters["searched"] = summary.images_searched;
  state.counters["GB"] = static_cast<double>(fs::file_size(recording.path)) / 1e9;
  state.SetLabel(kRecordingFormats[format]);
}
BENCHMARK(BM_ImportSimRecording)
    ->Args({30, 0})
    ->Args({30, 1})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

extern "C" char** environ;

// Runs `argv` and returns its peak resident memory in MiB (-1 when it failed).
double PeakMiBOf(std::vector<std::string> argv) {
  std::vector<char*> args;
  for (std::string& arg : argv) args.push_back(arg.data());
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1.0;
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return -1.0;
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

void BM_ImportPeakMemory(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const int format = static_cast<int>(state.range(1));
  const BenchRecording& recording = Recording(poses, format);
  const fs::path out = recording.path.string() + ".peak.dataset";
  double peak = 0.0;
  for (auto _ : state) {
    fs::remove_all(out);
    peak = PeakMiBOf({CALIBENCH_EXE_PATH, "import", recording.path.string(), "--board", "a3", "-o",
                      out.string()});
    if (peak < 0) state.SkipWithError("calibench import failed");
  }
  state.counters["peak_MiB"] = peak;
  state.counters["GB"] = static_cast<double>(fs::file_size(recording.path)) / 1e9;
  state.SetLabel(kRecordingFormats[format]);
}
BENCHMARK(BM_ImportPeakMemory)
    ->Args({19, 0})
    ->Args({19, 1})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

// One hold's messages of a small recording, kept in memory.
struct HoldMessages {
  std::vector<std::uint8_t> cloud_a, cloud_b;
  std::vector<std::vector<std::uint8_t>> images;
  test::SimRecordingTruth truth;
};

class Collect : public test::RecordingWriter {
 public:
  explicit Collect(HoldMessages* hold) : hold_(hold) {}
  void Add(const test::RecordedMessage& message) override {
    if (message.topic == "/velodyne_points") {
      if (hold_->cloud_a.empty())
        hold_->cloud_a = message.data;
      else if (hold_->cloud_b.empty())
        hold_->cloud_b = message.data;
    } else if (message.topic == "/camera/image_raw" && hold_->images.size() < 7) {
      hold_->images.push_back(message.data);
    }
  }
  void Close() override {}

 private:
  HoldMessages* hold_;
};

const HoldMessages& OneHold() {
  static const HoldMessages hold = [] {
    HoldMessages messages;
    test::SimRecordingOptions options;
    options.poses = 1;
    options.hold_s = 1.0;
    Collect collect(&messages);
    messages.truth = test::WriteSimRecording(&collect, MessageEncoding::kCdr, options);
    return messages;
  }();
  return hold;
}

void BM_ImportSweep(benchmark::State& state) {
  const HoldMessages& hold = OneHold();
  const CloudMotionOptions options;
  const SweepGrid first =
      MakeSweepGrid(DecodePointCloud2(hold.cloud_a, MessageEncoding::kCdr).cloud, options);
  for (auto _ : state) {
    const LidarCloud cloud = DecodePointCloud2(hold.cloud_b, MessageEncoding::kCdr).cloud;
    const SweepChange change = CompareSweeps(first, MakeSweepGrid(cloud, options), options);
    benchmark::DoNotOptimize(change);
  }
}
BENCHMARK(BM_ImportSweep)->Unit(benchmark::kMillisecond);

void BM_ImportImageStamp(benchmark::State& state) {
  const HoldMessages& hold = OneHold();
  for (auto _ : state) {
    // What the reader does with every image: its stamp, and a copy for the stillness window.
    std::vector<std::uint8_t> copy = hold.images[0];
    benchmark::DoNotOptimize(DecodeRosHeader(copy, MessageEncoding::kCdr));
  }
}
BENCHMARK(BM_ImportImageStamp)->Unit(benchmark::kMillisecond);

void BM_ImportTry(benchmark::State& state) {
  const HoldMessages& hold = OneHold();
  std::vector<ImageU8> images;
  for (const auto& bytes : hold.images)
    images.push_back(DecodeImage(bytes, MessageEncoding::kCdr).image);
  const CameraModel& camera = hold.truth.camera;
  for (auto _ : state) {
    std::string why;
    const auto detection = DetectBoard(images[0], hold.truth.board, {}, &why);
    if (!detection) state.SkipWithError(why.c_str());
    benchmark::DoNotOptimize(EstimateBoardPose(camera, *detection, {}, &why));
    for (std::size_t i = 1; i < 6; ++i) {
      const auto tracked = TrackBoard(images[0], *detection, images[i], 0.8, &why);
      if (tracked) benchmark::DoNotOptimize(EstimateBoardPose(camera, *tracked, {}, &why));
    }
  }
}
BENCHMARK(BM_ImportTry)->Unit(benchmark::kMillisecond);

void BM_ImportSearchEveryImage(benchmark::State& state) {
  const HoldMessages& hold = OneHold();
  const ImageU8 image = DecodeImage(hold.images[0], MessageEncoding::kCdr).image;
  for (auto _ : state) {
    std::string why;
    benchmark::DoNotOptimize(DetectBoard(image, hold.truth.board, {}, &why));
  }
}
BENCHMARK(BM_ImportSearchEveryImage)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace calibench
