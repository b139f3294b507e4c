// calibench import: a ROS 1 / ROS 2 recording -> a dataset folder (or --list its topics).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <tuple>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/progress_listener.h"
#include "core/capture/bag_import.h"
#include "core/capture/rig_import.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/io/json_io.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"

namespace calibench::app {
namespace fs = std::filesystem;

namespace {

const char* EncodingLabel(const BagTopic& topic) {
  return topic.encoding == MessageEncoding::kOther  ? topic.encoding_name.c_str()
         : topic.encoding == MessageEncoding::kRos1 ? "ros1"
                                                    : "cdr";
}

bool Importable(const std::string& type) {
  return IsCloudType(type) || type == kImageType || type == kCompressedImageType ||
         type == kCameraInfoType;
}

void PrintTopics(const BagReader& bag) {
  std::printf("%s: %s, %.1f MB\n", bag.Path().c_str(), bag.Format().c_str(),
              static_cast<double>(bag.SizeBytes()) / 1e6);
  std::size_t width = 5;
  for (const BagTopic& topic : bag.Topics()) width = std::max(width, topic.name.size());
  std::printf("  %-*s  %-32s %-5s %8s  %s\n", static_cast<int>(width), "topic", "type", "enc",
              "messages", "import");
  std::vector<BagTopic> topics = bag.Topics();
  std::sort(topics.begin(), topics.end(), [](const BagTopic& a, const BagTopic& b) {
    return std::tie(a.name, a.type) < std::tie(b.name, b.type);
  });
  for (const BagTopic& topic : topics)
    std::printf("  %-*s  %-32s %-5s %8lld  %s\n", static_cast<int>(width), topic.name.c_str(),
                topic.type.c_str(), EncodingLabel(topic),
                static_cast<long long>(topic.message_count),
                !Importable(topic.type)                     ? "-"
                : topic.encoding == MessageEncoding::kOther ? "no (not ROS 1 or CDR)"
                                                            : "yes");
}

// "[=====     ] 48% reading 120/250 MB" on a terminal; a line per 10 % elsewhere.
ImportProgress ProgressBar() {
  const bool terminal = isatty(fileno(stderr));
  return [terminal, last = std::string(), last_tenth = -1](
             const std::string& phase, std::int64_t done, std::int64_t total) mutable {
    const int percent = total > 0 ? static_cast<int>(100 * done / total) : 100;
    if (terminal) {
      std::string bar(20, ' ');
      std::fill(bar.begin(), bar.begin() + percent / 5, '=');
      std::fprintf(stderr, "\r[%s] %3d%% %s %.0f/%.0f MB%s", bar.c_str(), percent, phase.c_str(),
                   done / 1e6, total / 1e6, percent == 100 ? "\n" : "");
    } else if (phase != last || percent / 10 != last_tenth) {
      std::fprintf(stderr, "%s %d%%\n", phase.c_str(), percent);
    }
    if (phase != last) last_tenth = -1;
    last = phase;
    last_tenth = percent / 10;
    NotifyProgress(phase, done, total, "");
  };
}

// How import chooses its pairs (core/capture/recording_pairs.h), as flags.
void AddSelectionFlags(CLI::App& app, PairSelectionOptions* options_out) {
  PairSelectionOptions& options = *options_out;
  app.add_option("--max-offset", options.max_pair_offset_s,
                 "largest cloud-image stamp difference [s]")
      ->capture_default_str();
  app.add_option("--still-window", options.still_window_s,
                 "the board must stand still over this window around each pair [s]")
      ->capture_default_str();
  app.add_option("--still-translation", options.still_translation_m,
                 "largest board movement within the window [m]")
      ->capture_default_str();
  app.add_option("--still-rotation", options.still_rotation_deg,
                 "largest board rotation within the window [deg]")
      ->capture_default_str();
  app.add_option("--duplicate-translation", options.duplicate_translation_m,
                 "a pair closer than this to a kept one (and within --duplicate-rotation) is a "
                 "near-duplicate [m]")
      ->capture_default_str();
  app.add_option("--duplicate-rotation", options.duplicate_rotation_deg,
                 "see --duplicate-translation [deg]")
      ->capture_default_str();
  app.add_option("--moving-after", options.moving_after_s,
                 "a board that never stops (waved): once the LiDAR has seen nothing still for "
                 "this long, every sweep that sees the board is a pair with the camera frames "
                 "around it (0: still holds only) [s]")
      ->capture_default_str();
}

void PrintSummary(const BagImportSummary& summary, const BagImportOptions& options) {
  std::printf("%s\n", summary.format.c_str());
  if (!summary.cut_short.empty())
    std::printf("note: %s: the pairs below are those held before that point\n",
                summary.cut_short.c_str());
  std::printf("clouds  %-28s %lld messages\n", summary.cloud_topic.c_str(),
              static_cast<long long>(summary.clouds));
  if (!summary.point_times.empty())
    std::printf("        %s (%d of the pairs written keep them, field t)\n",
                summary.point_times.c_str(), summary.pairs_with_point_times);
  std::printf("images  %-28s %lld messages; searched %d for the board, found in %d\n",
              summary.image_topic.c_str(), static_cast<long long>(summary.images),
              summary.images_searched, summary.boards_seen);
  std::printf("board   %s\n", summary.board_source.c_str());
  std::printf("camera  %s\n", summary.camera_source.c_str());
  std::printf("pairs written: %zu\n", summary.pair_ids.size());
  if (summary.moving_pairs > 0)
    std::printf(
        "  %d of them moving: sweeps of a board that never stopped, each with the camera "
        "frames around it\n",
        summary.moving_pairs);
  for (const auto& [reason, count] : summary.dropped)
    std::printf("  dropped %5d  %s\n", count, reason.c_str());
  if (summary.kept_without_stillness_check > 0)
    std::printf(
        "  note: %d pairs had no other image within %.0f ms, so their stillness was not "
        "checked\n",
        summary.kept_without_stillness_check, options.still_window_s * 500);
  std::printf("dataset: %s\n", summary.manifest.c_str());
}

}  // namespace

std::optional<BoardSpec> BoardFromFlag(const std::string& board) {
  if (board.empty()) return std::nullopt;
  std::error_code error;
  if (fs::is_regular_file(board, error)) return LoadTargetFile(board);
  return BoardPreset(board);
}

// The rig's flags and --calibrate.
struct RigFlags {
  std::vector<std::string> camera_topics;
  bool all_cameras = false;
  bool calibrate = false;
};

void AddRigFlags(CLI::App& app, RigFlags* rig) {
  app.add_option("--camera-topic", rig->camera_topics,
                 "a rig: one Image or CompressedImage topic per camera (repeat the flag); the "
                 "folder is then the rig's form (images/<camera>/, cameras/<camera>.yaml), each "
                 "camera named after its topic")
      ->excludes("--image-topic");
  app.add_flag("--all-cameras", rig->all_cameras,
               "a rig: every image topic with a CameraInfo beside it is a camera (as "
               "--camera-topic for each)")
      ->excludes("--image-topic")
      ->excludes("--camera-topic");
  app.add_flag("--calibrate", rig->calibrate,
               "then calibrate the folder written (a rig: every camera, then the rig) and write "
               "result.json (rig.json for a rig) into it");
}

// One camera: the dataset folder, how fast, then (--calibrate) its calibration.
int ImportOneCamera(const std::string& bag_path, const std::string& out,
                    const std::optional<BoardSpec>& board, const BagImportOptions& options,
                    bool calibrate) {
  const auto start = std::chrono::steady_clock::now();
  const BagImportSummary summary = ImportBag(bag_path, out, board, options, ProgressBar());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PrintSummary(summary, options);
  // The last line of a log: what came out and how fast, against the recording's own length.
  std::fprintf(stderr, "imported %zu pairs from %.0f MB in %.1f s", summary.pair_ids.size(),
               summary.bytes_read / 1e6, seconds);
  if (summary.recording_seconds > 0)
    std::fprintf(stderr, " (the recording spans %.1f s: %.2fx its length)",
                 summary.recording_seconds, seconds / summary.recording_seconds);
  std::fprintf(stderr, "\n");
  if (!calibrate) return kOk;
  return CalibrateAndReport(LoadDataset(out), PipelineOptions{},
                            (fs::path(out) / "result.json").string());
}

// A rig (--camera-topic A --camera-topic B, or --all-cameras): the rig's folder form, then
// (--calibrate) every camera and the rig.
int ImportRigFolder(const std::string& bag_path, const std::string& out,
                    const std::optional<BoardSpec>& board, const BagImportOptions& options,
                    const RigFlags& flags) {
  const std::vector<std::string> topics =
      flags.all_cameras ? CameraTopicsWithInfo(*OpenBag(bag_path)) : flags.camera_topics;
  if (topics.empty()) {
    std::fprintf(stderr, "calibench import: %s: no image topic has a CameraInfo beside it\n",
                 bag_path.c_str());
    return kInputError;
  }
  const RigImportSummary summary = ImportRig(bag_path, out, board, options, topics, ProgressBar());
  for (size_t c = 0; c < summary.cameras.size(); ++c) {
    std::printf("camera %s (%s):\n", summary.camera_names[c].c_str(), topics[c].c_str());
    PrintSummary(summary.cameras[c], options);
  }
  std::printf("rig folder %s: %d captures, %d seen by two or more cameras\n", out.c_str(),
              summary.captures, summary.shared_captures);
  if (!flags.calibrate) return kOk;
  const RigOutcome outcome = CalibrateRig(LoadRigFolder(out), PipelineOptions{});
  std::printf("%s", FormatRigSummary(outcome).c_str());
  if (!outcome.joint) {
    std::fprintf(stderr, "calibench: no calibration for the rig %s: %s\n", out.c_str(),
                 outcome.failure.c_str());
    return kNoCalibration;
  }
  const fs::path result = fs::path(out) / "rig.json";
  WriteRigResult(result, outcome);
  std::printf("wrote %s\n", result.c_str());
  return kOk;
}

int RunImport(int argc, char** argv) {
  CLI::App app{
      "Turn a recording into a dataset folder (binary PCD + PNG + camera.yaml + dataset.json): "
      "ROS 1 .bag (uncompressed, bz2, lz4), ROS 2 .db3 or .mcap (or a rosbag2 folder); no ROS "
      "installation needed. Clouds are paired with the nearest image; only moments when the "
      "board stood still are kept, near-duplicate poses dropped, and every dropped frame is "
      "counted by reason.",
      "calibench import"};
  std::string bag_path, out, board, target, camera_file;
  bool list = false;
  BagImportOptions options;
  app.add_option("bag", bag_path, "the recording (.bag, .db3, .mcap, or a rosbag2 folder)")
      ->required();
  app.add_flag("--list", list, "print the topics, their types and message counts, and stop");
  app.add_option("--out,-o", out,
                 "dataset folder to write (default: <bag name>.dataset beside it, or under "
                 "~/.local/share/calibench/imports when that folder is read-only)");
  CLI::Option* board_option = AddBoardOption(app, &board, "the board the camera sees");
  app.add_option("--target", target, "the board as a target.json (same as --board FILE)")
      ->check(CLI::ExistingFile)
      ->excludes(board_option);
  app.add_option("--cloud-topic", options.cloud_topic, "PointCloud2 topic (default: the only one)");
  app.add_option("--image-topic", options.image_topic,
                 "Image or CompressedImage topic (default: the only one)");
  app.add_option("--camera-info-topic", options.camera_info_topic,
                 "CameraInfo topic (default: the one beside the image topic)");
  RigFlags rig;
  AddRigFlags(app, &rig);
  app.add_option("--camera", camera_file,
                 "intrinsics file instead of the recording's CameraInfo (OpenCV, ROS or Kalibr)");
  AddSelectionFlags(app, &options);
  app.add_option("--max-pairs", options.max_pairs, "at most this many pairs (0 = no cap)")
      ->capture_default_str();
  if (const auto code = ParseFlags(app, argc, argv)) return *code;

  if (list) {
    PrintTopics(*OpenBag(bag_path));
    return kOk;
  }
  std::optional<BoardSpec> board_spec;
  try {
    board_spec = BoardFromFlag(target.empty() ? board : target);
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "calibench import: --board: %s\n", error.what());
    return kUsage;
  }
  if (!camera_file.empty()) options.camera = LoadCameraFile(camera_file);
  std::string why;
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench import: %s\n", why.c_str());
    return kUsage;
  }
  if (out.empty()) out = DefaultImportFolder(bag_path).string();
  if (rig.all_cameras || !rig.camera_topics.empty())
    return ImportRigFolder(bag_path, out, board_spec, options, rig);
  return ImportOneCamera(bag_path, out, board_spec, options, rig.calibrate);
}
}  // namespace calibench::app
