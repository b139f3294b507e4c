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

json TerminationToJson(const Termination& termination) {
  json out = {{"test", TerminationTestName(termination.test)},
              {"value", termination.value},
              {"tolerance", termination.tolerance},
              {"text", termination.Describe()}};
  if (termination.test == TerminationTest::kIterationCap) out["cap"] = termination.cap;
  return out;
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
  const json document = json_io::ReadJson(path);
  const json_io::Fields root(document, path);
  json_io::CheckFormat(root, "calibench.result.v1");
  const char* key = root.Has("cam_from_lidar") ? "cam_from_lidar" : "cam_from_lrf";
  if (!root.Has(key)) json_io::Fail(path, "has neither cam_from_lidar nor cam_from_lrf");
  LoadedResult result;
  const json_io::Fields pose = root.Object(key);
  // As written, bit for bit: a result read back equals the one the solver returned.
  result.cam_from_source.matrix() =
      json_io::RigidMatrixFromJson(pose.At("matrix"), path, pose.Path("matrix"));
  // The uncertainty is optional, so that a hand-written transform can serve as --initial-guess.
  if (root.Has("covariance_6x6")) {
    const json& covariance = root.Array("covariance_6x6", 6);
    for (int r = 0; r < 6; ++r) {
      const std::string where = "covariance_6x6[" + std::to_string(r) + "]";
      const json& row = json_io::ArrayAt(covariance[r], 6, path, where);
      for (int c = 0; c < 6; ++c) result.covariance(r, c) = json_io::NumberAt(row[c], path, where);
    }
  }
  if (root.Has("observability"))
    result.well_constrained = root.Object("observability").Bool("well_constrained");
  if (root.Has("time_offset"))
    result.camera_minus_lidar_s = root.Object("time_offset").Number("camera_minus_lidar_s");
  return result;
}

std::string ResultSolverMethod(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const json result = json::parse(in, nullptr, false);
  if (result.is_discarded() || !result.contains("solver") || !result["solver"].is_object())
    return "";
  const json& method = result["solver"].value("method", json());
  return method.is_string() ? method.get<std::string>() : "";
}

bool IsLrfResultFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const json result = json::parse(in, nullptr, false);
  return result.is_object() && result.contains("cam_from_lrf");
}

}  // namespace calibench
