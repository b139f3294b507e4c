#include "core/io/dataset.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "core/base/atomic_file.h"
#include "core/base/names.h"
#include "core/geometry/geometry.h"
#include "core/io/assets.h"
#include "core/io/camera_file.h"
#include "core/io/dataset_source.h"
#include "core/io/json_io.h"

namespace calibench {
namespace fs = std::filesystem;
using nlohmann::json;

using json_io::Fail;

namespace {

constexpr char kFormat[] = "calibench.dataset.v1";

// What a command that takes one camera says when it is given a rig (folder or manifest).
[[noreturn]] void FailRig(const fs::path& path, const char* form) {
  Fail(path, std::string("a rig ") + form +
                 " (several cameras by name): `calibench calibrate --dataset` calibrates every "
                 "camera and the rig; `calibench gui` and `render` take `--camera <name>` for one "
                 "of them");
}

// "lidar_stamp_ns": nanoseconds as a decimal string (what JSON readers that hold numbers as
// doubles keep exactly) or an integer.
std::optional<std::int64_t> ParseStampNs(const json_io::Fields& p, const std::string& key) {
  if (!p.Has(key)) return std::nullopt;
  const json& value = p.At(key);
  if (value.is_number_integer()) return value.get<std::int64_t>();
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    std::int64_t ns = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), ns);
    if (error == std::errc() && end == text.data() + text.size() && !text.empty()) return ns;
  }
  p.Fail(key, "must be nanoseconds as an integer or a decimal string (\"1604515190231000000\")");
}

PairEntry ParsePair(const json_io::Fields& p, std::set<std::string>* seen) {
  const fs::path base = p.file().parent_path();
  PairEntry pair;
  pair.id = p.String("id");
  json_io::CheckUniquePairId(pair.id, seen, p.file());
  pair.cloud = json_io::Resolve(base, p.String("cloud"));
  pair.lidar_seed = json_io::ParseLidarSeed(p);
  pair.lidar_stamp_ns = ParseStampNs(p, "lidar_stamp_ns");
  if (!p.Has("images")) {
    pair.image = json_io::Resolve(base, p.String("image"));
    return pair;
  }
  // A moving capture: the frames around the sweep, each with its stamp on the camera's clock.
  if (p.Has("image")) p.Fail("images", "a pair gives \"image\" or \"images\", not both");
  if (!pair.lidar_stamp_ns)
    p.Fail("images",
           "needs the pair's \"lidar_stamp_ns\": the frames' stamps are compared with it");
  const json& frames = p.Array("images");
  if (frames.empty()) p.Fail("images", "is empty");
  for (size_t k = 0; k < frames.size(); ++k) {
    const json_io::Fields frame(frames[k], p.file(),
                                p.Path("images") + "[" + std::to_string(k) + "]");
    const std::optional<std::int64_t> stamp = ParseStampNs(frame, "stamp_ns");
    if (!stamp) frame.Fail("stamp_ns", "missing");
    pair.images.push_back({json_io::Resolve(base, frame.String("image")), *stamp});
  }
  std::stable_sort(
      pair.images.begin(), pair.images.end(),
      [](const StampedImage& a, const StampedImage& b) { return a.stamp_ns < b.stamp_ns; });
  const auto nearest = std::min_element(pair.images.begin(), pair.images.end(),
                                        [&](const StampedImage& a, const StampedImage& b) {
                                          return std::llabs(a.stamp_ns - *pair.lidar_stamp_ns) <
                                                 std::llabs(b.stamp_ns - *pair.lidar_stamp_ns);
                                        });
  pair.image = nearest->image;
  return pair;
}

SimulationRecord ParseSimulation(const json_io::Fields& sim) {
  SimulationRecord record;
  record.lidar_model = sim.String("lidar_model");
  record.num_pairs = sim.Int("num_pairs");
  record.min_distance_m = sim.Number("min_distance_m");
  record.max_distance_m = sim.Number("max_distance_m");
  record.max_tilt_deg = sim.Number("max_tilt_deg");
  record.lidar_range_noise_m = sim.Number("lidar_range_noise_m");
  record.lidar_frame_s = sim.GetOr("lidar_frame_s", 0.0);  // Livox-class models only
  // Manifests written before the offset existed have none.
  record.lidar_range_offset_m = sim.GetOr("lidar_range_offset_m", 0.0);
  record.lidar_angular_noise_rad = sim.GetOr("lidar_angular_noise_rad", 0.0);
  record.image_noise = sim.Number("image_noise");
  record.clutter = sim.Bool("clutter");
  record.board_only_clouds = sim.GetOr("board_only_clouds", false);  // written since issue 32
  record.lidar_viewpoints = sim.GetOr("lidar_viewpoints", false);    // written only when true
  record.seed_radius_m = sim.Number("seed_radius_m");
  record.seed = sim.Get<std::uint64_t>("seed");
  return record;
}

Dataset LoadManifest(const fs::path& manifest) {
  const json document = json_io::ReadJson(manifest);
  const json_io::Fields root(document, manifest);
  Dataset dataset;
  dataset.manifest = manifest;
  json_io::CheckFormat(root, kFormat);
  if (root.Has("cameras") && !root.Has("camera") && !root.Has("camera_file"))
    FailRig(manifest, "manifest");
  dataset.camera = json_io::ParseManifestCamera(root);
  dataset.target = json_io::ParseTarget(root.Object("target"));
  if (root.Has("lidar")) dataset.lidar_rings = root.Object("lidar").GetOr("rings", 0);
  std::set<std::string> seen;
  const json& pairs = json_io::PairsArray(root);
  for (size_t i = 0; i < pairs.size(); ++i)
    dataset.pairs.push_back(
        ParsePair(json_io::Fields(pairs[i], manifest, "pairs[" + std::to_string(i) + "]"), &seen));
  dataset.cam_from_lidar_ground_truth =
      json_io::OptionalPose(root, "ground_truth", "cam_from_lidar");
  if (root.Has("simulation")) dataset.simulation = ParseSimulation(root.Object("simulation"));
  return dataset;
}

// Folder shorthand: clouds/ and images/ paired by file stem, camera.yaml, target.json.
Dataset LoadFolder(const fs::path& dir, CameraFile camera, TargetFile target) {
  Dataset dataset = LoadFolderSetup(dir, camera, target);
  auto list = [&](const char* sub) {
    std::map<std::string, fs::path, NaturalOrder> by_stem;  // pose2 before pose10
    if (!fs::is_directory(dir / sub)) Fail(dir, std::string("folder dataset has no ") + sub + "/");
    for (const auto& entry : fs::directory_iterator(dir / sub)) {
      // Everything but folders is listed: a broken link, a loop of links or a FIFO becomes its
      // pair's failure when that pair's files are read, naming the file and the problem, instead
      // of ending the whole dataset here (or vanishing from it).
      std::error_code ec;
      if (!entry.is_directory(ec)) by_stem[entry.path().stem().string()] = entry.path();
    }
    return by_stem;
  };
  const auto clouds = list("clouds");
  const auto images = list("images");
  for (const auto& [stem, cloud] : clouds) {
    const auto image = images.find(stem);
    if (image == images.end()) continue;
    dataset.pairs.push_back(PairEntry{stem, cloud, image->second, std::nullopt});
  }
  if (dataset.pairs.empty()) Fail(dir, "no cloud/image pairs share a file stem");
  return dataset;
}

}  // namespace

Dataset LoadFolderSetup(const fs::path& dir, CameraFile camera, TargetFile target) {
  Dataset dataset;
  dataset.manifest = dir;
  const fs::path camera_file = dir / "camera.yaml";
  const fs::path target_file = dir / "target.json";
  const bool has_camera = fs::exists(camera_file);
  if (!has_camera && fs::is_directory(dir / "cameras"))
    FailRig(dir, "folder (cameras/<camera>.yaml, images/<camera>/)");
  if (!has_camera && camera == CameraFile::kRequired)
    Fail(dir,
         "folder dataset has no camera.yaml (and no dataset.json): put the camera's intrinsics "
         "there (OpenCV YAML, ROS camera_info or a Kalibr camchain), or estimate them from the "
         "images (`calibench intrinsics`, `calibrate --estimate-intrinsics`)");
  const bool has_target = fs::exists(target_file);
  if (!has_target && target == TargetFile::kRequired)
    Fail(dir, "folder dataset has no target.json (and no dataset.json)");
  if (has_camera) {
    dataset.camera = LoadCameraFile(camera_file);
  } else {
    dataset.missing_camera_file = camera_file;
  }
  if (has_target)
    dataset.target = LoadTargetFile(target_file);
  else
    dataset.missing_target_file = target_file;
  return dataset;
}

BoardSpec LoadTargetFile(const fs::path& path) {
  const json document = json_io::ReadJson(path);
  const json_io::Fields target(document, path);
  return json_io::ParseTarget(target.Has("target") ? target.Object("target") : target);
}

void SaveTargetFile(const fs::path& path, const BoardSpec& board) {
  WriteFileAtomically(path, json_io::TargetToJson(board).dump(2) + "\n");
}

Dataset LoadDataset(const fs::path& path, CameraFile camera, TargetFile target) {
  const DatasetSource source = ResolveDataset(path, DatasetKind::kLidarCamera);
  return source.folder_form ? LoadFolder(fs::absolute(source.path), camera, target)
                            : LoadManifest(fs::absolute(source.path));
}

void SaveDataset(const fs::path& manifest_path, const Dataset& dataset) {
  auto relative = [&](const fs::path& p) { return json_io::PathForManifest(p, manifest_path); };
  json root;
  root["format"] = kFormat;
  root["camera"] = json_io::CameraToJson(dataset.camera);
  root["target"] = json_io::TargetToJson(dataset.target);
  if (dataset.lidar_rings > 0) root["lidar"] = {{"rings", dataset.lidar_rings}};
  json pairs = json::array();
  for (const PairEntry& p : dataset.pairs) {
    json entry = {{"id", p.id}, {"cloud", relative(p.cloud)}};
    if (p.images.empty()) {
      entry["image"] = relative(p.image);
    } else {
      json frames = json::array();
      for (const StampedImage& frame : p.images)
        frames.push_back(
            {{"image", relative(frame.image)}, {"stamp_ns", std::to_string(frame.stamp_ns)}});
      entry["images"] = frames;
    }
    if (p.lidar_seed)
      entry["lidar_seed"] = {
          {"point", {p.lidar_seed->point.x(), p.lidar_seed->point.y(), p.lidar_seed->point.z()}},
          {"radius", p.lidar_seed->radius}};
    if (p.lidar_stamp_ns) entry["lidar_stamp_ns"] = std::to_string(*p.lidar_stamp_ns);
    pairs.push_back(entry);
  }
  root["pairs"] = pairs;
  if (dataset.cam_from_lidar_ground_truth)
    root["ground_truth"] = {
        {"cam_from_lidar", json_io::MatrixToJson(dataset.cam_from_lidar_ground_truth->matrix())},
        {"direction", "x_in_cam = cam_from_lidar * x_in_lidar"}};
  if (dataset.simulation) {
    const SimulationRecord& r = *dataset.simulation;
    root["simulation"] = {{"lidar_model", r.lidar_model},
                          {"num_pairs", r.num_pairs},
                          {"min_distance_m", r.min_distance_m},
                          {"max_distance_m", r.max_distance_m},
                          {"max_tilt_deg", r.max_tilt_deg},
                          {"lidar_range_noise_m", r.lidar_range_noise_m},
                          {"image_noise", r.image_noise},
                          {"clutter", r.clutter},
                          {"board_only_clouds", r.board_only_clouds},
                          {"seed_radius_m", r.seed_radius_m},
                          {"seed", r.seed},
                          {"lidar_range_offset_m", r.lidar_range_offset_m},
                          {"lidar_angular_noise_rad", r.lidar_angular_noise_rad}};
    if (r.lidar_frame_s > 0) root["simulation"]["lidar_frame_s"] = r.lidar_frame_s;
    if (r.lidar_viewpoints) root["simulation"]["lidar_viewpoints"] = true;
  }
  WriteFileAtomically(manifest_path, root.dump(2) + "\n");
}

std::vector<std::pair<std::string, BoardSpec>> ShippedTargetPresets() {
  std::vector<std::pair<std::string, BoardSpec>> presets;
  try {
    for (const auto& entry : std::filesystem::directory_iterator(FindAsset("targets")))
      if (entry.path().extension() == ".json")
        presets.emplace_back(entry.path().stem().string(), LoadTargetFile(entry.path()));
  } catch (const IoError&) {
    presets.clear();
    for (const char* name : {"a3", "a4", "charuco-a3", "charuco-a4", "paper"})
      presets.emplace_back(name, BoardPreset(name));
  }
  std::sort(presets.begin(), presets.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  return presets;
}

}  // namespace calibench
