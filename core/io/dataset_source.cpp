#include "core/io/dataset_source.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/base/types.h"
#include "core/io/recording_kind.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

constexpr char kLidarCameraFormat[] = "calibench.dataset.v1";
constexpr char kLrfFormat[] = "calibench.lrf-dataset.v1";
// A manifest is small; a larger file is not read whole to learn that it is not one.
constexpr std::uintmax_t kMaxManifestBytes = 256ull << 20;

constexpr char kLookedFor[] =
    "looked for a manifest (a JSON file whose \"format\" is calibench.dataset.v1 or "
    "calibench.lrf-dataset.v1: the file itself, or in the folder dataset.json, manifest.json or "
    "any other *.json), the folder form (clouds/ and images/ beside camera.yaml and "
    "target.json) and a recording (ROS 1 .bag, MCAP, rosbag2 .db3 or its folder)";

// The manifest kind of a JSON file, or nullopt with *why (the file and the problem). *broken
// (optional) is set when the file is no JSON at all (cut mid-object, a stray comma): *why then
// holds the parser's words, with the line and the column.
std::optional<DatasetKind> ManifestKind(const fs::path& file, std::string* why,
                                        bool* broken = nullptr) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec || size > kMaxManifestBytes) {
    *why = file.string() + ": " + (ec ? "cannot be read" : "too large for a manifest");
    return std::nullopt;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    *why = file.string() + ": cannot be opened";
    return std::nullopt;
  }
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {  // a syntax error, a number out of range
    *why = file.string() + ": not valid JSON: " + e.what();
    if (broken) *broken = true;
    return std::nullopt;
  }
  if (!root.is_object()) {
    *why = file.string() + ": not a JSON object";
    return std::nullopt;
  }
  const auto format = root.find("format");
  if (format == root.end() || !format->is_string()) {
    *why = file.string() + ": JSON without a \"format\" field";
    return std::nullopt;
  }
  const std::string name = format->get<std::string>();
  if (name == kLidarCameraFormat) return DatasetKind::kLidarCamera;
  if (name == kLrfFormat) return DatasetKind::kLrf;
  *why = file.string() + ": a " + name + " file, not a dataset manifest";
  return std::nullopt;
}

bool IsDirectory(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

std::optional<DatasetSource> RecogniseFolder(const fs::path& folder, std::string* why) {
  std::vector<std::string> problems;
  // The usual names first, so that a folder holding both kinds opens as it always did.
  for (const char* name : {"dataset.json", "manifest.json"}) {
    const fs::path file = folder / name;
    std::error_code ec;
    if (!fs::exists(file, ec)) continue;
    std::string problem;
    bool broken = false;
    if (const auto kind = ManifestKind(file, &problem, &broken))
      return DatasetSource{*kind, file, false};
    // The folder's own manifest, damaged: its parse error, never another file opened silently
    // in its place (the edits the user made to it would be lost without a word).
    if (broken) {
      *why = problem + " (the folder's manifest: fix it, or name the manifest to open)";
      return std::nullopt;
    }
    problems.push_back(problem);
  }
  std::vector<DatasetSource> others;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const fs::path& file = entry.path();
    if (file.extension() != ".json" || file.filename() == "dataset.json" ||
        file.filename() == "manifest.json" || IsDirectory(file))
      continue;
    std::string ignored;
    if (const auto kind = ManifestKind(file, &ignored)) others.push_back({*kind, file, false});
  }
  if (others.size() == 1) return others.front();
  if (others.size() > 1) {
    std::sort(others.begin(), others.end(),
              [](const DatasetSource& a, const DatasetSource& b) { return a.path < b.path; });
    std::string names;
    for (const DatasetSource& other : others)
      names += (names.empty() ? "" : ", ") + other.path.filename().string();
    *why =
        folder.string() + ": holds several dataset manifests (" + names + "): name the one to open";
    return std::nullopt;
  }
  if (IsDirectory(folder / "clouds") && IsDirectory(folder / "images"))
    return DatasetSource{DatasetKind::kLidarCamera, folder, true};
  if (LooksLikeBag(folder)) return DatasetSource{DatasetKind::kRecording, folder, false};
  std::string found;
  for (const std::string& problem : problems) found += "; " + problem;
  *why = folder.string() + ": not a dataset folder (" + kLookedFor + ")" + found;
  return std::nullopt;
}

}  // namespace

std::string DatasetKindName(DatasetKind kind) {
  switch (kind) {
    case DatasetKind::kLidarCamera:
      return "LiDAR-camera dataset (calibench.dataset.v1)";
    case DatasetKind::kLrf:
      return "2D LRF dataset (calibench.lrf-dataset.v1)";
    case DatasetKind::kRecording:
      return "recording";
  }
  return "dataset";
}

std::optional<DatasetSource> RecogniseDataset(const fs::path& path, std::string* why) {
  std::error_code ec;
  if (path.empty()) {
    *why = "no dataset given";
    return std::nullopt;
  }
  if (!fs::exists(path, ec)) {
    *why = path.string() + ": no such file or folder";
    return std::nullopt;
  }
  if (IsDirectory(path)) return RecogniseFolder(path, why);
  std::string problem;
  if (const auto kind = ManifestKind(path, &problem)) return DatasetSource{*kind, path, false};
  if (LooksLikeBag(path)) return DatasetSource{DatasetKind::kRecording, path, false};
  *why = problem + " (" + kLookedFor + ")";
  return std::nullopt;
}

DatasetSource ResolveDataset(const fs::path& path, DatasetKind wanted) {
  std::string why;
  const std::optional<DatasetSource> source = RecogniseDataset(path, &why);
  if (!source) {
    // A file named outright that is no manifest nor recording: its loader says best what is
    // wrong with it (the parse error and its position, the wrong format string).
    std::error_code ec;
    if (fs::is_regular_file(path, ec)) return DatasetSource{wanted, path, false};
    throw IoError(why);
  }
  if (source->kind == wanted) return *source;
  std::string how;
  switch (source->kind) {
    case DatasetKind::kLidarCamera:
      how = "open it with `calibench calibrate --dataset`";
      break;
    case DatasetKind::kLrf:
      how = "open it with `calibench lrf-calibrate --dataset`";
      break;
    case DatasetKind::kRecording:
      how =
          "turn it into a dataset folder first: `calibench import " + path.string() + " --out DIR`";
      break;
  }
  throw IoError(path.string() + ": a " + DatasetKindName(source->kind) + ", not a " +
                DatasetKindName(wanted) + ": " + how);
}

}  // namespace calibench
