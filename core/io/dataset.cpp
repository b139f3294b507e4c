#include "core/io/dataset.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/geometry/geometry.h"
#include "core/io/camera_file.h"
#include "core/io/json_io.h"

namespace calibench {
namespace fs = std::filesystem;
using nlohmann::json;

using json_io::Fail;
using json_io::Get;
using json_io::MatrixToJson;
using json_io::ParseInlineCamera;
using json_io::ParseTarget;
using json_io::PoseFromJson;
using json_io::ReadJson;
using json_io::Resolve;
using json_io::TargetToJson;

namespace {

Dataset LoadManifest(const fs::path& manifest) {
  const json root = ReadJson(manifest);
  const fs::path base = manifest.parent_path();
  Dataset dataset;
  dataset.manifest = manifest;
  const std::string format = root.value("format", "");
  if (format != "calibench.dataset.v1")
    Fail(manifest, "format is '" + format + "', expected 'calibench.dataset.v1'");
  dataset.camera = json_io::ParseManifestCamera(root, manifest);
  if (!root.contains("target")) Fail(manifest, "missing field 'target'");
  dataset.target = ParseTarget(root.at("target"), manifest);
  if (root.contains("lidar")) dataset.lidar_rings = root.at("lidar").value("rings", 0);
  if (!root.contains("pairs") || !root.at("pairs").is_array())
    Fail(manifest, "missing array 'pairs'");
  std::map<std::string, int> seen;
  for (const json& p : root.at("pairs")) {
    PairEntry pair;
    pair.id = Get<std::string>(p, "id", manifest, "pairs[].");
    if (seen[pair.id]++) Fail(manifest, "pair id '" + pair.id + "' appears twice");
    pair.cloud = Resolve(base, Get<std::string>(p, "cloud", manifest, "pairs[" + pair.id + "]."));
    pair.image = Resolve(base, Get<std::string>(p, "image", manifest, "pairs[" + pair.id + "]."));
    if (p.contains("lidar_seed")) {
      const json& s = p.at("lidar_seed");
      const auto point = Get<std::vector<double>>(s, "point", manifest, "lidar_seed.");
      if (point.size() != 3)
        Fail(manifest, "pair " + pair.id + ": lidar_seed.point must be [x, y, z]");
      LidarSeed seed{Vec3(point[0], point[1], point[2]),
                     Get<double>(s, "radius", manifest, "lidar_seed.")};
      if (!(seed.radius > 0) || !seed.point.allFinite())
        Fail(manifest, "pair " + pair.id + ": lidar_seed needs a finite point and a radius > 0");
      pair.lidar_seed = seed;
    }
    dataset.pairs.push_back(pair);
  }
  if (root.contains("ground_truth") && root.at("ground_truth").contains("cam_from_lidar"))
    dataset.cam_from_lidar_ground_truth = PoseFromJson(root.at("ground_truth").at("cam_from_lidar"),
                                                       manifest, "ground_truth.cam_from_lidar");
  if (root.contains("simulation")) {
    const json& sim = root.at("simulation");
    SimulationRecord record;
    record.lidar_model = Get<std::string>(sim, "lidar_model", manifest, "simulation.");
    record.num_pairs = Get<int>(sim, "num_pairs", manifest, "simulation.");
    record.min_distance_m = Get<double>(sim, "min_distance_m", manifest, "simulation.");
    record.max_distance_m = Get<double>(sim, "max_distance_m", manifest, "simulation.");
    record.max_tilt_deg = Get<double>(sim, "max_tilt_deg", manifest, "simulation.");
    record.lidar_range_noise_m = Get<double>(sim, "lidar_range_noise_m", manifest, "simulation.");
    // Manifests written before the offset existed have none.
    record.lidar_range_offset_m =
        sim.contains("lidar_range_offset_m")
            ? Get<double>(sim, "lidar_range_offset_m", manifest, "simulation.")
            : 0.0;
    record.image_noise = Get<double>(sim, "image_noise", manifest, "simulation.");
    record.clutter = Get<bool>(sim, "clutter", manifest, "simulation.");
    record.seed_radius_m = Get<double>(sim, "seed_radius_m", manifest, "simulation.");
    record.seed = Get<std::uint64_t>(sim, "seed", manifest, "simulation.");
    dataset.simulation = record;
  }
  return dataset;
}

// Folder shorthand: clouds/ and images/ paired by file stem, camera.yaml, target.json.
Dataset LoadFolder(const fs::path& dir) {
  Dataset dataset;
  dataset.manifest = dir;
  const fs::path camera_file = dir / "camera.yaml";
  const fs::path target_file = dir / "target.json";
  if (!fs::exists(camera_file))
    Fail(dir, "folder dataset has no camera.yaml (and no dataset.json)");
  if (!fs::exists(target_file))
    Fail(dir, "folder dataset has no target.json (and no dataset.json)");
  dataset.camera = LoadCameraFile(camera_file);
  json target = ReadJson(target_file);
  dataset.target =
      ParseTarget(target.contains("target") ? target.at("target") : target, target_file);
  auto list = [&](const char* sub) {
    std::map<std::string, fs::path> by_stem;
    if (!fs::is_directory(dir / sub)) Fail(dir, std::string("folder dataset has no ") + sub + "/");
    for (const auto& entry : fs::directory_iterator(dir / sub))
      if (entry.is_regular_file()) by_stem[entry.path().stem().string()] = entry.path();
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

Dataset LoadDataset(const fs::path& path) {
  if (!fs::exists(path)) Fail(path, "no such file or folder");
  if (fs::is_directory(path)) {
    if (fs::exists(path / "dataset.json")) return LoadManifest(fs::absolute(path / "dataset.json"));
    return LoadFolder(fs::absolute(path));
  }
  return LoadManifest(fs::absolute(path));
}

void SaveDataset(const fs::path& manifest_path, const Dataset& dataset) {
  auto relative = [&](const fs::path& p) { return json_io::PathForManifest(p, manifest_path); };
  json root;
  root["format"] = "calibench.dataset.v1";
  root["camera"] = json_io::CameraToJson(dataset.camera);
  root["target"] = TargetToJson(dataset.target);
  if (dataset.lidar_rings > 0) root["lidar"] = {{"rings", dataset.lidar_rings}};
  json pairs = json::array();
  for (const PairEntry& p : dataset.pairs) {
    json entry = {{"id", p.id}, {"cloud", relative(p.cloud)}, {"image", relative(p.image)}};
    if (p.lidar_seed)
      entry["lidar_seed"] = {
          {"point", {p.lidar_seed->point.x(), p.lidar_seed->point.y(), p.lidar_seed->point.z()}},
          {"radius", p.lidar_seed->radius}};
    pairs.push_back(entry);
  }
  root["pairs"] = pairs;
  if (dataset.cam_from_lidar_ground_truth)
    root["ground_truth"] = {
        {"cam_from_lidar", MatrixToJson(dataset.cam_from_lidar_ground_truth->matrix())},
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
                          {"seed_radius_m", r.seed_radius_m},
                          {"seed", r.seed},
                          {"lidar_range_offset_m", r.lidar_range_offset_m}};
  }
  WriteFileAtomically(manifest_path, root.dump(2) + "\n");
}

}  // namespace calibench
