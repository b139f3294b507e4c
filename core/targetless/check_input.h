// The scenes a check reads (docs/targetless.md "Input"): every pair of a dataset folder or
// manifest, or clouds of a recording paired with the nearest image, reduced to their edges as
// they are read (a frame's edges are a few MB; its cloud and image are dropped).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/io/dataset.h"
#include "core/targetless/check.h"

namespace calibench {

struct CheckInputOptions {
  // Recordings: at most one frame per this interval (a still rig repeats itself), a cloud paired
  // with the image nearest in time within max_pair_offset_s, at most max_frames spread evenly.
  double frame_interval_s = 0.5;
  double max_pair_offset_s = 0.05;
  int max_frames = 40;
  std::string cloud_topic, image_topic, camera_info_topic;  // empty: chosen as `import` does
  std::optional<CameraModel> camera;                        // instead of camera.yaml/CameraInfo
  int threads = 0;                                          // 0 = DefaultThreads()

  bool Check(std::string* why) const;
};

struct CheckInput {
  CameraModel camera;
  std::vector<EdgeFrame> frames;
  std::string source;  // "dataset" or the recording's format
  // Frames that could not be read, each "file: reason"; the check goes on without them.
  std::vector<std::string> unreadable;
};

// Progress while reading: frames done (of total when known, else 0), the frame's id.
using CheckInputProgress = std::function<void(int done, int total, const std::string& id)>;

// A dataset (folder form or manifest) or a recording, recognised as every command does
// (core/io/dataset_source.h). Throws IoError naming the path when it cannot be read, has no
// camera intrinsics, or gives no frame at all.
CheckInput LoadCheckInput(const std::filesystem::path& path, const CheckOptions& check,
                          const CheckInputOptions& options,
                          const CheckInputProgress& progress = {});

// The same for a dataset already read (the workbench's): every pair's cloud and image read again
// from its files, as `check` reads them. Throws IoError naming the manifest when no frame reads.
CheckInput LoadDatasetCheckInput(const Dataset& dataset, const CheckOptions& check,
                                 const CheckInputOptions& options,
                                 const CheckInputProgress& progress = {});

}  // namespace calibench
