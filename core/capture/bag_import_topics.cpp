// What an import reads from a recording before any message: its options checked, where the
// dataset folder goes by default, and which topics carry the clouds, the images and the camera
// info (core/capture/bag_import.h).
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <set>

#include "core/capture/bag_import.h"
#include "core/recording/ros_messages.h"

namespace calibench {
namespace fs = std::filesystem;

bool BagImportOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (!(max_pair_offset_s > 0)) return fail("max pair offset must be > 0 s");
  if (!(still_window_s >= 0)) return fail("stillness window must be >= 0 s");
  if (!(still_translation_m > 0) || !(still_rotation_deg > 0))
    return fail("stillness thresholds must be > 0");
  if (!(duplicate_translation_m >= 0) || !(duplicate_rotation_deg >= 0))
    return fail("near-duplicate thresholds must be >= 0");
  if (max_pairs < 0) return fail("the pair cap must be >= 0 (0 = none)");
  std::string camera_why;
  if (camera && !camera->Check(&camera_why)) return fail("camera: " + camera_why);
  return PairSelectionOptions::Check(why);
}

std::optional<fs::path> TargetBesideRecording(const fs::path& bag) {
  fs::path source = fs::absolute(bag).lexically_normal();
  if (source.filename().empty()) source = source.parent_path();  // "folder/"
  const fs::path beside = source.parent_path();
  std::error_code error;
  // Named after the recording (rig.mcap: rig.target.json or rig.mcap.target.json), then the
  // folder's own target.json (inside a rosbag2 folder, then beside it).
  for (const fs::path& candidate : {beside / (source.stem().string() + ".target.json"),
                                    beside / (source.filename().string() + ".target.json"),
                                    source / "target.json", beside / "target.json"})
    if (fs::is_regular_file(candidate, error)) return candidate;
  // Else the only target file `calibench target` left beside it (board.pdf -> board.target.json).
  std::optional<fs::path> only;
  for (const fs::directory_entry& entry : fs::directory_iterator(beside, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= 12 || name.compare(name.size() - 12, 12, ".target.json") != 0 ||
        !entry.is_regular_file(error))
      continue;
    if (only) return std::nullopt;  // several: which one is the user's to say (--board)
    only = entry.path();
  }
  return only;
}

fs::path DefaultImportFolder(const fs::path& bag) {
  fs::path source = fs::absolute(bag).lexically_normal();
  if (source.filename().empty()) source = source.parent_path();  // "folder/"
  const fs::path beside = source.parent_path();
  const std::string name = source.filename().string() + ".dataset";
  if (::access(beside.c_str(), W_OK) == 0) return beside / name;
  const char* data = std::getenv("XDG_DATA_HOME");
  const char* home = std::getenv("HOME");
  const fs::path root =
      data && *data ? fs::path(data) : fs::path(home && *home ? home : "/tmp") / ".local/share";
  return root / "calibench" / "imports" / name;
}

namespace {

bool IsImageType(const std::string& type) {
  return type == kImageType || type == kCompressedImageType;
}

std::string Namespace(const std::string& topic) {
  const std::size_t slash = topic.rfind('/');
  return slash == std::string::npos ? "" : topic.substr(0, slash);
}

std::string Candidates(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? "none" : text;
}

std::vector<std::string> TopicsOfType(const BagReader& bag,
                                      const std::function<bool(const std::string&)>& type_ok) {
  std::vector<std::string> names;
  for (const BagTopic& topic : bag.Topics())
    if (type_ok(topic.type) && topic.message_count > 0 &&
        std::find(names.begin(), names.end(), topic.name) == names.end())
      names.push_back(topic.name);
  return names;
}

// Checks a named topic, or picks the only candidate; throws listing the candidates otherwise.
void ChooseOne(const BagReader& bag, const std::vector<std::string>& candidates, const char* what,
               const char* flag, std::string* chosen) {
  if (!chosen->empty()) {
    if (std::find(candidates.begin(), candidates.end(), *chosen) == candidates.end())
      throw IoError(bag.Path().string() + ": " + flag + " " + *chosen + " is not a " + what +
                    " topic with messages here (those are: " + Candidates(candidates) + ")");
    return;
  }
  if (candidates.size() == 1) {
    *chosen = candidates.front();
    return;
  }
  throw IoError(bag.Path().string() + ": " +
                (candidates.empty() ? std::string("no ") + what + " topic with messages"
                                    : std::string("several ") + what + " topics (" +
                                          Candidates(candidates) + "); choose one with " + flag));
}

}  // namespace

void ChooseTopics(const BagReader& bag, BagImportOptions* options) {
  ChooseOne(bag, TopicsOfType(bag, IsCloudType), "cloud (PointCloud2, Livox CustomMsg)",
            "--cloud-topic", &options->cloud_topic);
  std::vector<std::string> images = TopicsOfType(bag, IsImageType);
  // image_transport republishes a raw topic as <topic>/compressed: the same camera, once.
  std::erase_if(images, [&](const std::string& name) {
    return name.ends_with("/compressed") &&
           std::find(images.begin(), images.end(), Namespace(name)) != images.end();
  });
  ChooseOne(bag, images, "image", "--image-topic", &options->image_topic);
  if (options->camera) return;
  std::vector<std::string> infos =
      TopicsOfType(bag, [](const std::string& t) { return t == kCameraInfoType; });
  if (options->camera_info_topic.empty() && infos.size() > 1) {
    const std::string image_namespace = Namespace(options->image_topic);
    std::vector<std::string> beside;
    for (const std::string& info : infos)
      if (Namespace(info) == image_namespace) beside.push_back(info);
    if (beside.size() == 1) infos = beside;
  }
  if (infos.empty() && options->camera_info_topic.empty())
    throw IoError(bag.Path().string() +
                  ": no CameraInfo topic with messages: give the intrinsics with --camera FILE");
  ChooseOne(bag, infos, "CameraInfo", "--camera-info-topic", &options->camera_info_topic);
}

std::vector<std::string> CameraTopicsWithInfo(const BagReader& bag) {
  std::vector<std::string> images = TopicsOfType(bag, IsImageType);
  std::erase_if(images, [&](const std::string& name) {
    return name.ends_with("/compressed") &&
           std::find(images.begin(), images.end(), Namespace(name)) != images.end();
  });
  const std::vector<std::string> infos =
      TopicsOfType(bag, [](const std::string& t) { return t == kCameraInfoType; });
  std::erase_if(images, [&](const std::string& image) {
    return std::none_of(infos.begin(), infos.end(), [&](const std::string& info) {
      return Namespace(info) == Namespace(image) ||
             (image.ends_with("/compressed") && Namespace(info) == Namespace(Namespace(image)));
    });
  });
  return images;
}

}  // namespace calibench
