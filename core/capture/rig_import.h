// A recording with several camera topics -> the rig's folder form (core/io/rig_folder.h): each
// camera's pairs chosen as `import` chooses them for that camera (the board held still in its
// frames), then joined by the LiDAR sweep they share, so that a capture two cameras saw is one
// stem in clouds/ with a frame in each camera's images/<camera>/.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/capture/bag_import.h"

namespace calibench {

struct RigImportSummary {
  std::vector<std::string> camera_names;  // images/<name>/, cameras/<name>.yaml
  std::vector<BagImportSummary> cameras;  // each camera's import, as `import` reports it
  int captures = 0;                       // stems in clouds/
  int shared_captures = 0;                // of those, the ones two or more cameras have
};

// The camera's name in the rig folder from its image topic: the topic's first namespace that is
// not a generic word ("/cam1/image_raw" -> "cam1", "/front/camera/image/compressed" -> "front"),
// else the topic with '/' turned to '_'.
std::string RigCameraName(const std::string& image_topic);

// Imports one camera per topic in `image_topics` (its CameraInfo the one beside it, as import
// chooses) into `out_dir` in the rig's folder form. Reads the recording once per camera. Throws
// IoError as ImportBag does, naming the camera's topic.
RigImportSummary ImportRig(const std::filesystem::path& bag_path,
                           const std::filesystem::path& out_dir,
                           const std::optional<BoardSpec>& board, const BagImportOptions& options,
                           const std::vector<std::string>& image_topics,
                           const ImportProgress& progress = {});

}  // namespace calibench
