#include "core/targetless/check_input.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "core/base/parallel.h"
#include "core/capture/bag_import.h"
#include "core/io/cloud_io.h"
#include "core/io/dataset.h"
#include "core/io/dataset_source.h"
#include "core/io/image_io.h"
#include "core/recording/bag.h"
#include "core/recording/ros_messages.h"
#include "core/targetless/frame_pairer.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

int Threads(int threads) { return threads > 0 ? threads : DefaultThreads(); }

// A check needs one frame at least: none read is an error naming the source and why.
CheckInput RequireFrames(CheckInput input, const fs::path& path) {
  if (input.frames.empty()) {
    std::string reasons;
    for (const std::string& r : input.unreadable) reasons += "; " + r;
    throw IoError(path.string() + ": no frame to check (no cloud with an image)" + reasons);
  }
  return input;
}

}  // namespace

CheckInput LoadDatasetCheckInput(const Dataset& dataset, const CheckOptions& check,
                                 const CheckInputOptions& options,
                                 const CheckInputProgress& progress) {
  CheckInput input;
  input.camera = options.camera ? *options.camera : dataset.camera;
  input.source = "dataset";
  const size_t n = dataset.pairs.size();
  std::vector<std::optional<EdgeFrame>> frames(n);
  std::vector<std::string> problems(n);
  ParallelFor(
      n, Threads(options.threads),
      [&](size_t i) {
        const PairEntry& pair = dataset.pairs[i];
        try {
          const LidarCloud cloud = LoadCloud(pair.cloud);
          const ImageU8 image = LoadImage(pair.image);
          if (image.width != input.camera.width || image.height != input.camera.height)
            throw IoError(pair.image.string() + ": the image is " + std::to_string(image.width) +
                          "x" + std::to_string(image.height) + ", the camera " +
                          std::to_string(input.camera.width) + "x" +
                          std::to_string(input.camera.height));
          frames[i] = MakeEdgeFrame(pair.id, cloud, image, check);
        } catch (const std::exception& e) {
          problems[i] = e.what();
        }
      },
      [&](int done, size_t i) {
        if (progress) progress(done, static_cast<int>(n), dataset.pairs[i].id);
      });
  for (size_t i = 0; i < n; ++i) {
    if (frames[i]) input.frames.push_back(std::move(*frames[i]));
    if (!problems[i].empty()) input.unreadable.push_back(problems[i]);
  }
  return RequireFrames(std::move(input), dataset.manifest);
}

namespace {

// A whole recording read in file order through the pairer.
CheckInput LoadRecordingFrames(const fs::path& path, const CheckOptions& check,
                               const CheckInputOptions& options,
                               const CheckInputProgress& progress) {
  const std::unique_ptr<BagReader> bag = OpenBag(path);
  const CheckTopics chosen = ChooseCheckTopics(*bag, options);
  const PairTopics& topics = chosen.encodings;
  const int cloud_topic = chosen.cloud, image_topic = chosen.image;
  const int info_topic = chosen.camera_info;
  std::optional<CameraModel> camera = options.camera;
  std::vector<bool> wanted(bag->Topics().size(), false);
  wanted[cloud_topic] = wanted[image_topic] = true;
  if (info_topic >= 0) wanted[info_topic] = true;
  CheckFramePairer pairer(path.string(), topics, check, options, progress);
  bag->ForEachMessage(wanted, [&](const BagMessage& message) {
    if (message.topic == cloud_topic)
      pairer.AddCloud(message.data, message.log_time_ns);
    else if (message.topic == image_topic)
      pairer.AddImage(message.data, message.log_time_ns);
    else if (!camera)
      camera = DecodeCameraInfo(message.data, topics.camera_info).camera;
    return true;
  });
  if (!camera)
    throw IoError(path.string() + ": no camera intrinsics: the recording has no CameraInfo on " +
                  chosen.camera_info_name + "; give them with --camera FILE");
  CheckInput input;
  input.camera = *camera;
  input.source = bag->Format();
  input.unreadable = pairer.TakeProblems();
  std::vector<EdgeFrame> frames = pairer.TakeFrames();
  // At most max_frames, spread evenly over the recording.
  const size_t n = frames.size(), keep = std::min<size_t>(n, options.max_frames);
  for (size_t k = 0; k < keep; ++k) input.frames.push_back(std::move(frames[k * n / keep]));
  return input;
}

}  // namespace

bool CheckInputOptions::Check(std::string* why) const {
  auto fail = [&](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(frame_interval_s >= 0)) return fail("the frame interval must be >= 0 s");
  if (!(max_pair_offset_s > 0)) return fail("the pairing offset must be > 0 s");
  if (max_frames < 1) return fail("at least one frame");
  if (camera && !camera->Check(why)) return false;
  return true;
}

CheckInput LoadCheckInput(const fs::path& path, const CheckOptions& check,
                          const CheckInputOptions& options, const CheckInputProgress& progress) {
  std::string why;
  const std::optional<DatasetSource> source = RecogniseDataset(path, &why);
  if (source && source->kind == DatasetKind::kRecording)
    return RequireFrames(LoadRecordingFrames(path, check, options, progress), path);
  return LoadDatasetCheckInput(
      LoadDataset(path, options.camera ? CameraFile::kOptional : CameraFile::kRequired,
                  TargetFile::kOptional),
      check, options, progress);
}

}  // namespace calibench
