#include "core/capture/rig_import.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

#include "core/io/dataset.h"

namespace calibench {
namespace fs = std::filesystem;

std::string RigCameraName(const std::string& image_topic) {
  static const std::set<std::string> kGeneric = {
      "camera", "image", "image_raw", "image_rect", "image_color", "compressed", "color", "rgb"};
  std::string part;
  for (size_t i = 0; i <= image_topic.size(); ++i) {
    if (i < image_topic.size() && image_topic[i] != '/') {
      part += image_topic[i];
      continue;
    }
    if (!part.empty() && !kGeneric.count(part)) return part;
    part.clear();
  }
  std::string name = image_topic;
  for (char& c : name)
    if (c == '/') c = '_';
  while (!name.empty() && name.front() == '_') name.erase(name.begin());
  return name.empty() ? "camera" : name;
}

RigImportSummary ImportRig(const fs::path& bag_path, const fs::path& out_dir,
                           const std::optional<BoardSpec>& board, const BagImportOptions& options,
                           const std::vector<std::string>& image_topics,
                           const ImportProgress& progress) {
  RigImportSummary summary;
  std::vector<fs::path> staging;
  for (const std::string& topic : image_topics) {
    std::string name = RigCameraName(topic);
    for (int n = 2; std::find(summary.camera_names.begin(), summary.camera_names.end(), name) !=
                    summary.camera_names.end();
         ++n)
      name = RigCameraName(topic) + "_" + std::to_string(n);
    BagImportOptions camera = options;
    camera.image_topic = topic;
    camera.camera_info_topic.clear();  // the one beside this topic
    const fs::path dir = out_dir / (".import-" + name);
    fs::remove_all(dir);
    try {
      summary.cameras.push_back(ImportBag(bag_path, dir, board, camera, progress));
    } catch (const IoError& e) {
      for (const fs::path& d : staging) fs::remove_all(d);
      fs::remove_all(dir);
      throw IoError(std::string(e.what()) + " (camera topic " + topic + ")");
    }
    summary.camera_names.push_back(name);
    staging.push_back(dir);
  }
  // One stem per LiDAR sweep any camera kept, in time order.
  std::map<std::int64_t, std::string> stems;
  for (const BagImportSummary& camera : summary.cameras)
    for (std::int64_t stamp : camera.pair_cloud_stamps_ns) stems[stamp];
  int index = 0;
  for (auto& [stamp, stem] : stems) {
    char text[16];
    std::snprintf(text, sizeof(text), "%04d", index++);
    stem = text;
  }
  fs::create_directories(out_dir / "clouds");
  fs::create_directories(out_dir / "cameras");
  std::map<std::string, int> cameras_per_stem;
  for (size_t c = 0; c < summary.cameras.size(); ++c) {
    const BagImportSummary& camera = summary.cameras[c];
    const std::string& name = summary.camera_names[c];
    fs::create_directories(out_dir / "images" / name);
    for (size_t i = 0; i < camera.pair_ids.size(); ++i) {
      const std::string& stem = stems[camera.pair_cloud_stamps_ns[i]];
      const fs::path cloud = out_dir / "clouds" / (stem + ".pcd");
      if (++cameras_per_stem[stem] == 1)
        fs::rename(staging[c] / "clouds" / (camera.pair_ids[i] + ".pcd"), cloud);
      fs::rename(staging[c] / "images" / (camera.pair_ids[i] + ".png"),
                 out_dir / "images" / name / (stem + ".png"));
    }
    fs::rename(staging[c] / "camera.yaml", out_dir / "cameras" / (name + ".yaml"));
    fs::remove_all(staging[c]);
    summary.cameras[c].manifest = out_dir;  // the rig folder; the camera's own manifest is gone
  }
  SaveTargetFile(out_dir / "target.json", summary.cameras.front().board);
  summary.captures = static_cast<int>(stems.size());
  for (const auto& [stem, count] : cameras_per_stem) summary.shared_captures += count > 1;
  return summary;
}

}  // namespace calibench
