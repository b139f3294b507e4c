#include "core/results/result_file.h"

#include <cstdio>
#include <fstream>

#include "core/base/atomic_file.h"
#include "core/io/json_io.h"
#include "core/results/result_json.h"

namespace calibench {
using nlohmann::json;

json ResultHeaderJson(const ResultNames& names, const Pose& target_from_source,
                      const Mat6& covariance, const ObservabilityReport& observability) {
  const std::string forward = names.target + "_from_" + names.source;
  const std::string backward = names.source + "_from_" + names.target;
  json root;
  root["format"] = "calibench.result.v1";
  root["direction"] = "x_in_" + names.target + " = " + forward + " * x_in_" + names.source + "; " +
                      backward + " is its inverse";
  root[forward] = json_io::PoseToResultJson(target_from_source);
  root[backward] = json_io::PoseToResultJson(target_from_source.inverse());
  json cov = json::array();
  for (int r = 0; r < 6; ++r) {
    json row = json::array();
    for (int c = 0; c < 6; ++c) row.push_back(covariance(r, c));
    cov.push_back(row);
  }
  root["covariance_6x6"] = cov;
  root["covariance_convention"] =
      "right perturbation " + forward + " * Exp(delta), delta = [rho (m); phi (rad)]";
  const Vec3 st = TranslationStd(covariance, target_from_source);
  const Vec3 sr = RotationStdDeg(covariance, target_from_source);
  root["std_translation_m"] = {st.x(), st.y(), st.z()};
  root["std_rotation_deg"] = {sr.x(), sr.y(), sr.z()};
  root["std_frame"] = "camera axes (x right, y down, z forward) of " + forward;
  root["observability"] = {
      {"eigenvalues",
       std::vector<double>(observability.eigenvalues.data(), observability.eigenvalues.data() + 6)},
      {"weak_directions", observability.weak_directions},
      {"well_constrained", observability.well_constrained}};
  return root;
}

json PairEntryJson(const std::string& id, PairStatus status, const std::string& reason) {
  return {{"id", id}, {"status", PairStatusName(status)}, {"reason", reason}};
}

std::string FormatTransform(const ResultNames& names, const Pose& target_from_source,
                            const Mat6& covariance) {
  std::string out;
  char line[256];
  auto print_pose = [&](const std::string& name, const std::string& words, const Pose& pose) {
    out += name + "  (" + words + ")\n";
    for (int r = 0; r < 3; ++r) {
      std::snprintf(line, sizeof(line), "  [% .6f % .6f % .6f | % .6f]\n", pose.matrix()(r, 0),
                    pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3));
      out += line;
    }
  };
  print_pose(names.target + "_from_" + names.source,
             "maps points from the " + names.source + " frame into the " + names.target + " frame",
             target_from_source);
  print_pose(names.source + "_from_" + names.target,
             "maps points from the " + names.target + " frame into the " + names.source +
                 " frame; its translation is the " + names.target + " position in the " +
                 names.source + " frame",
             target_from_source.inverse());
  const Vec3 st = TranslationStd(covariance, target_from_source) * 1000.0;
  const Vec3 sr = RotationStdDeg(covariance, target_from_source);
  std::snprintf(
      line, sizeof(line),
      "std (camera axes x/y/z) translation [mm]: %.2f %.2f %.2f   rotation [deg]: %.3f %.3f %.3f\n",
      st.x(), st.y(), st.z(), sr.x(), sr.y(), sr.z());
  return out + line;
}

void WriteResultJson(const std::filesystem::path& path, const json& root) {
  WriteFileAtomically(path, root.dump(2) + "\n");
}

LoadedResult LoadResult(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path.string() + ": cannot open result file");
  json root;
  try {
    root = json::parse(in);
  } catch (const json::exception& e) {
    throw IoError(path.string() + ": not valid JSON: " + e.what());
  }
  if (root.value("format", "") != "calibench.result.v1")
    throw IoError(path.string() + ": format is not calibench.result.v1");
  const char* key = root.contains("cam_from_lidar") ? "cam_from_lidar" : "cam_from_lrf";
  if (!root.contains(key))
    throw IoError(path.string() + ": has neither cam_from_lidar nor cam_from_lrf");
  LoadedResult result;
  try {
    const auto rows = root.at(key).at("matrix").get<std::vector<std::vector<double>>>();
    if (rows.size() != 4) throw IoError(path.string() + ": " + key + ".matrix must be 4x4");
    Mat4 m;
    for (int r = 0; r < 4; ++r) {
      if (rows[r].size() != 4) throw IoError(path.string() + ": " + key + ".matrix must be 4x4");
      for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c];
    }
    result.cam_from_source.matrix() = m;
    if (root.contains("covariance_6x6")) {
      const auto cov = root.at("covariance_6x6").get<std::vector<std::vector<double>>>();
      for (int r = 0; r < 6 && r < static_cast<int>(cov.size()); ++r)
        for (int c = 0; c < 6 && c < static_cast<int>(cov[r].size()); ++c)
          result.covariance(r, c) = cov[r][c];
    }
    result.well_constrained = root.at("observability").value("well_constrained", false);
  } catch (const json::exception& e) {
    throw IoError(path.string() + ": malformed result: " + e.what());
  }
  return result;
}

}  // namespace calibench
