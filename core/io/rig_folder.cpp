#include "core/io/rig_folder.h"

#include <map>

#include "core/base/names.h"
#include "core/io/camera_file.h"

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

}  // namespace

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
    camera.camera = LoadCameraFile(camera_file);
    camera.target = target;
    const fs::path images = rig.folder / "images" / name;
    if (!fs::is_directory(images))
      Fail(rig.folder, "camera '" + name + "' has no images/" + name + "/ folder");
    const auto frames = FilesByStem(images);
    for (const auto& [stem, cloud] : clouds)
      if (const auto frame = frames.find(stem); frame != frames.end())
        camera.pairs.push_back(PairEntry{stem, cloud, frame->second, std::nullopt});
    if (camera.pairs.empty())
      Fail(images, "no frame shares a stem with a cloud in clouds/ (camera '" + name + "')");
    rig.camera_names.push_back(name);
    rig.cameras.push_back(std::move(camera));
  }
  if (rig.cameras.empty()) Fail(rig.folder / "cameras", "no camera files (cameras/<camera>.yaml)");
  return rig;
}

}  // namespace calibench
