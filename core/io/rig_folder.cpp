#include "core/io/rig_folder.h"

#include <algorithm>
#include <map>
#include <set>

#include "core/base/names.h"
#include "core/io/camera_file.h"
#include "core/io/json_io.h"

namespace calibench {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void Fail(const fs::path& where, const std::string& problem) {
  throw IoError(where.string() + ": " + problem);
}

// The files of `dir` by stem, in natural order (pose2 before pose10); folders are skipped.
std::map<std::string, fs::path, NaturalOrder> FilesByStem(const fs::path& dir) {
  std::map<std::string, fs::path, NaturalOrder> by_stem;
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    std::error_code entry_error;
    if (!it->is_directory(entry_error)) by_stem[it->path().stem().string()] = it->path();
  }
  return by_stem;
}

constexpr char kManifestFormat[] = "calibench.dataset.v1";

// The rig manifest's cameras: inline, or {"file": ...} naming a camera file beside it.
CameraModel ParseRigCamera(const json_io::Fields& camera, const std::string& name) {
  const CameraModel model =
      camera.Has("file")
          ? LoadCameraFile(json_io::Resolve(camera.file().parent_path(), camera.String("file")))
          : json_io::ParseInlineCamera(camera);
  json_io::CheckOrFail(model, camera.file(), "cameras." + name);
  return model;
}

RigFolder LoadRigManifest(const fs::path& manifest) {
  const json_io::json document = json_io::ReadJson(manifest);
  const json_io::Fields root(document, manifest);
  json_io::CheckFormat(root, kManifestFormat);
  RigFolder rig;
  rig.folder = fs::absolute(manifest).lexically_normal();
  const json_io::Fields cameras = root.Object("cameras");
  std::vector<std::string> names;
  for (const auto& item : root.At("cameras").items()) names.push_back(item.key());
  std::sort(names.begin(), names.end(), NaturalOrder{});
  if (names.empty()) root.Fail("cameras", "names no camera");
  const BoardSpec target = json_io::ParseTarget(root.Object("target"));
  const int rings = root.Has("lidar") ? root.Object("lidar").GetOr("rings", 0) : 0;
  for (const std::string& name : names) {
    Dataset camera;
    camera.manifest = rig.folder;
    camera.camera_name = name;
    camera.camera = ParseRigCamera(cameras.Object(name), name);
    camera.target = target;
    camera.lidar_rings = rings;
    if (root.Has("ground_truth") && root.Object("ground_truth").Has("cameras")) {
      const json_io::Fields truth = root.Object("ground_truth").Object("cameras");
      if (truth.Has(name))
        camera.cam_from_lidar_ground_truth =
            json_io::OptionalPose(truth, name.c_str(), "cam_from_lidar");
    }
    rig.camera_names.push_back(name);
    rig.cameras.push_back(std::move(camera));
  }
  const fs::path base = rig.folder.parent_path();
  const json_io::json& pairs = json_io::PairsArray(root);
  std::set<std::string> seen;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const json_io::Fields pair(pairs[i], manifest, "pairs[" + std::to_string(i) + "]");
    PairEntry entry;
    entry.id = pair.String("id");
    json_io::CheckUniquePairId(entry.id, &seen, manifest);
    entry.cloud = json_io::Resolve(base, pair.String("cloud"));
    entry.lidar_seed = json_io::ParseLidarSeed(pair);
    const json_io::Fields images = pair.Object("images");
    for (const auto& item : pair.At("images").items()) {
      const auto at = std::find(names.begin(), names.end(), item.key());
      if (at == names.end())
        images.Fail(item.key(), "camera '" + item.key() + "' is not in cameras");
      entry.image = json_io::Resolve(base, images.String(item.key()));
      rig.cameras[at - names.begin()].pairs.push_back(entry);
    }
  }
  for (size_t c = 0; c < names.size(); ++c)
    if (rig.cameras[c].pairs.empty())
      root.Fail("pairs", "no pair has an image of camera '" + names[c] + "'");
  return rig;
}

}  // namespace

bool IsRig(const fs::path& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return IsRigFolder(path);
  if (!fs::is_regular_file(path, error)) return false;
  // A manifest names its cameras near the top; a large file is a cloud or a recording.
  if (fs::file_size(path, error) > json_io::kMaxJsonBytes) return false;
  try {
    const json_io::json document = json_io::ReadJson(path);
    return document.is_object() && document.contains("cameras") && !document.contains("camera") &&
           !document.contains("camera_file");
  } catch (const IoError&) {
    return false;
  }
}

RigFolder LoadRig(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error) ? LoadRigFolder(path) : LoadRigManifest(path);
}

RigFolder RigOfOne(const Dataset& dataset) {
  RigFolder rig;
  rig.folder = dataset.manifest;
  rig.camera_names = {dataset.camera_name.empty() ? "camera" : dataset.camera_name};
  rig.cameras = {dataset};
  return rig;
}

size_t RigCameraIndex(const RigFolder& rig, const std::string& camera) {
  const auto at = std::find(rig.camera_names.begin(), rig.camera_names.end(), camera);
  if (at != rig.camera_names.end()) return at - rig.camera_names.begin();
  std::string names;
  for (const std::string& name : rig.camera_names) names += (names.empty() ? "" : ", ") + name;
  Fail(rig.folder, "the rig has no camera '" + camera + "' (its cameras: " + names + ")");
}

Dataset LoadRigCamera(const fs::path& path, const std::string& camera) {
  RigFolder rig = LoadRig(path);
  return std::move(rig.cameras[RigCameraIndex(rig, camera)]);
}

bool IsRigFolder(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path / "cameras", error);
}

RigFolder LoadRigFolder(const fs::path& path) {
  RigFolder rig;
  rig.folder = fs::absolute(path).lexically_normal();
  if (!IsRigFolder(rig.folder))
    Fail(rig.folder, "not a rig folder: it has no cameras/ (cameras/<camera>.yaml per camera)");
  if (!fs::exists(rig.folder / "target.json")) Fail(rig.folder, "rig folder has no target.json");
  const BoardSpec target = LoadTargetFile(rig.folder / "target.json");
  const auto clouds = FilesByStem(rig.folder / "clouds");
  if (clouds.empty()) Fail(rig.folder / "clouds", "no clouds (clouds/<stem>.pcd)");
  for (const auto& [name, camera_file] : FilesByStem(rig.folder / "cameras")) {
    Dataset camera;
    camera.manifest = rig.folder;
    camera.camera_name = name;
    camera.camera = LoadCameraFile(camera_file);
    camera.target = target;
    const fs::path images = rig.folder / "images" / name;
    if (!fs::is_directory(images))
      Fail(rig.folder, "camera '" + name + "' has no images/" + name + "/ folder");
    const auto frames = FilesByStem(images);
    for (const auto& [stem, cloud] : clouds)
      if (const auto frame = frames.find(stem); frame != frames.end()) {
        PairEntry pair;
        pair.id = stem;
        pair.cloud = cloud;
        pair.image = frame->second;
        camera.pairs.push_back(std::move(pair));
      }
    if (camera.pairs.empty())
      Fail(images, "no frame shares a stem with a cloud in clouds/ (camera '" + name + "')");
    rig.camera_names.push_back(name);
    rig.cameras.push_back(std::move(camera));
  }
  if (rig.cameras.empty()) Fail(rig.folder / "cameras", "no camera files (cameras/<camera>.yaml)");
  return rig;
}

}  // namespace calibench
