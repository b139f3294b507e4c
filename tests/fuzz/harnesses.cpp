#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/base/types.h"
#include "core/io/camera_file.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "core/lrf_data/dataset.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "tests/fuzz/harness.h"

namespace calibench::fuzz {
namespace {

// One folder per process, so parallel fuzzing jobs (-jobs=N) never share an input file.
const std::filesystem::path& InputFolder() {
  static const std::filesystem::path folder = [] {
    auto path =
        std::filesystem::temp_directory_path() / ("calibench-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  return folder;
}

std::filesystem::path WriteInput(const std::vector<uint8_t>& bytes, const char* extension) {
  const std::filesystem::path path = InputFolder() / (std::string("input") + extension);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  return path;
}

template <typename Load>
void WithFile(const std::vector<uint8_t>& bytes, const char* extension, Load load) {
  load(WriteInput(bytes, extension));
}

// The depth seeds are 32 x 24 pixels; other sizes must be refused by name, not misread.
DepthIntrinsics FuzzDepthIntrinsics() {
  DepthIntrinsics intrinsics;
  intrinsics.width = 32;
  intrinsics.height = 24;
  intrinsics.fx = intrinsics.fy = 30.0;
  intrinsics.cx = 16.0;
  intrinsics.cy = 12.0;
  return intrinsics;
}

// One message as `calibench import` decodes it. The decoders refuse a bad message with
// std::invalid_argument (the import counts it as a dropped frame); nothing else may escape.
void DecodeLikeImport(const std::string& type, MessageEncoding encoding,
                      std::span<const std::uint8_t> data) {
  try {
    if (type == kPointCloud2Type) {
      DecodePointCloud2(data, encoding);
    } else if (type == kImageType) {
      DecodeImage(data, encoding);
    } else if (type == kCompressedImageType) {
      DecodeCompressedImage(data, encoding);
    } else if (type == kCameraInfoType) {
      DecodeCameraInfo(data, encoding);
    } else {
      DecodeRosHeader(data, encoding);
    }
  } catch (const std::invalid_argument&) {
  }
}

// A whole recording: its index, every message, each decoded as the import would.
void ReadRecording(const std::filesystem::path& path) {
  auto bag = OpenBag(path);
  bag->ForEachMessage({}, [&](const BagMessage& message) {
    const BagTopic& topic = bag->Topics()[message.topic];
    if (topic.encoding != MessageEncoding::kOther)
      DecodeLikeImport(topic.type, topic.encoding, message.data);
    return true;
  });
}

// One serialized message, without a file: the first byte picks the type (bits 0-1) and the
// serialization (bit 2: CDR), the rest is the message.
void DecodeMessageBytes(const std::vector<uint8_t>& bytes) {
  if (bytes.empty()) return;
  static const char* const types[] = {kPointCloud2Type, kImageType, kCompressedImageType,
                                      kCameraInfoType};
  DecodeLikeImport(types[bytes[0] & 3],
                   (bytes[0] & 4) ? MessageEncoding::kCdr : MessageEncoding::kRos1,
                   std::span<const std::uint8_t>(bytes).subspan(1));
}

#define CALIBENCH_FILE_TARGET(name, extension, call)                                     \
  FuzzTarget {                                                                           \
    name, extension, [](const std::vector<uint8_t>& bytes) {                             \
      WithFile(bytes, extension, [](const std::filesystem::path& path) { (void)call; }); \
    }                                                                                    \
  }

}  // namespace

const std::vector<FuzzTarget>& FuzzTargets() {
  static const std::vector<FuzzTarget> targets = {
      CALIBENCH_FILE_TARGET("pcd", ".pcd", LoadCloud(path)),
      CALIBENCH_FILE_TARGET("ply", ".ply", LoadCloud(path)),
      CALIBENCH_FILE_TARGET("kitti", ".bin", LoadCloud(path)),
      CALIBENCH_FILE_TARGET("dataset", ".json", LoadDataset(path)),
      CALIBENCH_FILE_TARGET("lrf_dataset", ".json", LoadLrfDataset(path)),
      CALIBENCH_FILE_TARGET("camera_yaml", ".yaml", LoadCameraFile(path)),
      CALIBENCH_FILE_TARGET("camera_xml", ".xml", LoadCameraFile(path)),
      CALIBENCH_FILE_TARGET("session", ".json", LoadSession(path)),
      CALIBENCH_FILE_TARGET("result", ".json", LoadResult(path)),
      CALIBENCH_FILE_TARGET("scan", ".json", LoadLaserScan(path)),
      CALIBENCH_FILE_TARGET("depth_png", ".png", LoadDepthPng(path, FuzzDepthIntrinsics())),
      CALIBENCH_FILE_TARGET("image", ".png", LoadImage(path)),
      CALIBENCH_FILE_TARGET("ros1_bag", ".bag", ReadRecording(path)),
      CALIBENCH_FILE_TARGET("mcap", ".mcap", ReadRecording(path)),
      CALIBENCH_FILE_TARGET("db3", ".db3", ReadRecording(path)),
      FuzzTarget{"ros_message", "", DecodeMessageBytes},
  };
  return targets;
}

const FuzzTarget* FindFuzzTarget(std::string_view name) {
  for (const FuzzTarget& target : FuzzTargets())
    if (name == target.name) return &target;
  return nullptr;
}

int RunFuzzInput(const FuzzTarget& target, const uint8_t* data, size_t size) {
  try {
    target.load(std::vector<uint8_t>(data, data + size));
  } catch (const IoError& e) {
    // The one accepted failure, provided its message names the file (the input, or a file the
    // input refers to, which lies beside it). A nameless message is a finding like a crash.
    if (std::string(e.what()).find(InputFolder().string()) == std::string::npos) {
      std::fprintf(stderr, "IoError without the file's name: %s\n", e.what());
      std::abort();
    }
    // CALIBENCH_FUZZ_VERBOSE=1 shows the refusals (for checking that seeds load).
    if (std::getenv("CALIBENCH_FUZZ_VERBOSE") != nullptr) std::fprintf(stderr, "  %s\n", e.what());
  }
  return 0;
}

}  // namespace calibench::fuzz
