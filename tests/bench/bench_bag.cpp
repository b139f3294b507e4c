// Import throughput on a 1 GB simulated recording in each format: a ROS 1 bag (uncompressed, as
// `rosbag record` writes by default), an MCAP of the ros2 profile uncompressed (as `ros2 bag
// record -s mcap` writes by default) and with zstd chunks, and a rosbag2 .db3. Throughput is the
// messages' bytes (about 1.02 GB in every format) per second; the zstd file is smaller. The
// recordings are written once into build/bench_bags/ (about 3 GB of disk) from an 8-pair demo
// simulation (OS0-128, 131k points; 1440 x 1080 bgr8): 56 moments, each a cloud and three images of
// a still board, cycling over the pairs.
//   BM_BagRead     every message handed out (MB/s of the file)
//   BM_BagDecode   every PointCloud2 and Image decoded too
//   BM_BagImport   `calibench import` as a whole: one pass, each moment tried (its clouds are
//                  alone in their stillness windows), the chosen pairs written as PCD + PNG
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/capture/bag_import.h"
#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "core/sim/sim.h"
#include "tests/bag_writers.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

const fs::path& BenchFolder() {
  static const fs::path folder = fs::absolute("bench_bags");
  return folder;
}

const Dataset& BenchDataset() {
  static const Dataset dataset = [] {
    SimOptions sim = SimPreset("demo");
    sim.num_pairs = 8;
    sim.seed = 4;
    return SimulateDataset(sim, BenchFolder() / "sim");
  }();
  return dataset;
}

std::vector<test::RecordedMessage> Moments(MessageEncoding encoding) {
  const Dataset& dataset = BenchDataset();
  std::vector<LidarCloud> clouds;
  std::vector<ImageU8> images;
  for (const PairEntry& pair : dataset.pairs) {
    clouds.push_back(LoadCloud(pair.cloud));
    images.push_back(LoadImage(pair.image));
  }
  std::vector<test::RecordedMessage> messages;
  for (int moment = 0; moment < 56; ++moment) {
    const std::size_t pair = moment % dataset.pairs.size();
    const std::int64_t t = (100 + moment) * 1'000'000'000LL;
    for (const std::int64_t offset : {-50'000'000LL, 0LL, 50'000'000LL}) {
      messages.push_back(
          {"/camera/image_raw", "sensor_msgs/Image", t + offset,
           test::SerializeImage(images[pair], "bgr8", t + offset, "camera", encoding)});
      messages.push_back(
          {"/camera/camera_info", "sensor_msgs/CameraInfo", t + offset,
           test::SerializeCameraInfo(dataset.camera, t + offset, "camera", encoding)});
    }
    messages.push_back({"/os_cloud_node/points", "sensor_msgs/PointCloud2", t + 10'000'000,
                        test::SerializePointCloud2(clouds[pair], t, "os_lidar", encoding)});
  }
  return messages;
}

const char* kFormats[] = {"bag", "mcap", "zstd.mcap", "db3"};

// The recording of kFormats[index], written on first use.
fs::path Recording(int index) {
  const std::string format = kFormats[index];
  const fs::path path = BenchFolder() / ("recording." + format);
  if (fs::exists(path)) return path;
  if (format == "bag") test::WriteRos1Bag(path, Moments(MessageEncoding::kRos1), "none");
  if (format == "mcap") test::WriteMcap(path, Moments(MessageEncoding::kCdr), "ros2", "");
  if (format == "zstd.mcap") test::WriteMcap(path, Moments(MessageEncoding::kCdr), "ros2", "zstd");
  if (format == "db3") test::WriteDb3(path, Moments(MessageEncoding::kCdr));
  return path;
}

// The bytes of all messages in a recording (the same in every format, up to the headers).
std::int64_t MessageBytes(const fs::path& path) {
  std::int64_t bytes = 0;
  OpenBag(path)->ForEachMessage({}, [&](const BagMessage& message) {
    bytes += static_cast<std::int64_t>(message.data.size());
    return true;
  });
  return bytes;
}

std::string Label(int index, const fs::path& path) {
  return std::string(kFormats[index]) + ", file " +
         std::to_string(fs::file_size(path) / 1'000'000) + " MB";
}

void BM_BagRead(benchmark::State& state) {
  const fs::path path = Recording(static_cast<int>(state.range(0)));
  state.SetLabel(Label(static_cast<int>(state.range(0)), path));
  for (auto _ : state) {
    auto bag = OpenBag(path);
    std::size_t bytes = 0;
    bag->ForEachMessage({}, [&](const BagMessage& message) {
      bytes += message.data.size();
      return true;
    });
    benchmark::DoNotOptimize(bytes);
  }
  state.SetBytesProcessed(state.iterations() * MessageBytes(path));
}
BENCHMARK(BM_BagRead)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BagDecode(benchmark::State& state) {
  const fs::path path = Recording(static_cast<int>(state.range(0)));
  state.SetLabel(Label(static_cast<int>(state.range(0)), path));
  for (auto _ : state) {
    auto bag = OpenBag(path);
    std::size_t points = 0, pixels = 0;
    bag->ForEachMessage({}, [&](const BagMessage& message) {
      const BagTopic& topic = bag->Topics()[message.topic];
      if (topic.type == kPointCloud2Type)
        points += DecodePointCloud2(message.data, topic.encoding).cloud.size();
      if (topic.type == kImageType)
        pixels += DecodeImage(message.data, topic.encoding).image.data.size();
      return true;
    });
    benchmark::DoNotOptimize(points + pixels);
  }
  state.SetBytesProcessed(state.iterations() * MessageBytes(path));
}
BENCHMARK(BM_BagDecode)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BagImport(benchmark::State& state) {
  const fs::path path = Recording(static_cast<int>(state.range(0)));
  const fs::path out = BenchFolder() / (std::string("imported.") + kFormats[state.range(0)]);
  std::size_t pairs = 0;
  for (auto _ : state) {
    fs::remove_all(out);
    pairs = ImportBag(path, out, BenchDataset().target, {}).pair_ids.size();
  }
  state.SetLabel(Label(static_cast<int>(state.range(0)), path) + ", " + std::to_string(pairs) +
                 " pairs written");
  state.SetBytesProcessed(state.iterations() * MessageBytes(path));
}
BENCHMARK(BM_BagImport)
    ->DenseRange(0, 3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace calibench
