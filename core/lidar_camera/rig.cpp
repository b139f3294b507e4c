#include "core/lidar_camera/rig.h"

#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/estimation/uncertainty.h"

namespace calibench {
namespace {

using Json = nlohmann::ordered_json;

Json Matrix4(const Pose& pose) {
  Json rows = Json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({pose(r, 0), pose(r, 1), pose(r, 2), pose(r, 3)});
  return rows;
}

Json Matrix6(const Mat6& m) {
  Json rows = Json::array();
  for (int r = 0; r < 6; ++r) {
    Json row = Json::array();
    for (int c = 0; c < 6; ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

Json Vector3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

// The pose with its σ in its own axes (translation mm, rotation deg).
Json PoseWithSigma(const Pose& pose, const Mat6& covariance) {
  return {{"matrix", Matrix4(pose)},
          {"sigma_translation_mm", Vector3(1e3 * TranslationStd(covariance, pose))},
          {"sigma_rotation_deg", Vector3(RotationStdDeg(covariance, pose))}};
}

}  // namespace

RigOutcome CalibrateRig(const RigFolder& rig, const PipelineOptions& options,
                        const ProgressCallback& progress) {
  RigOutcome outcome;
  outcome.camera_names = rig.camera_names;
  std::vector<Pose> initial;
  // Captures by stem: the LiDAR plane (the first camera's pair that has one) and every view.
  std::map<std::string, RigCapture, NaturalOrder> captures;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    outcome.single.push_back(CalibrateDataset(rig.cameras[c], options, progress));
    const CalibrationOutcome& single = outcome.single.back();
    if (!single.solution) {
      outcome.failure = "camera '" + rig.camera_names[c] + "': " + single.failure;
      continue;
    }
    initial.push_back(single.solution->cam_from_lidar);
    for (const PairFeatures& pair : single.pairs) {
      if (pair.status != PairStatus::kAccepted || !pair.lidar || !pair.camera) continue;
      RigCapture& capture = captures[pair.id];
      capture.id = pair.id;
      if (!capture.lidar_plane) {
        capture.lidar_plane = pair.lidar->plane;
        capture.lidar_covariance = pair.lidar->covariance;
      }
      capture.views.push_back(
          {static_cast<int>(c), pair.camera->cam_from_board, pair.camera->pose_covariance});
    }
  }
  if (!outcome.failure.empty()) return outcome;
  std::vector<RigCapture> all;
  for (auto& [stem, capture] : captures) {
    outcome.shared_captures += capture.views.size() > 1;
    all.push_back(std::move(capture));
  }
  std::string why;
  outcome.joint = SolveRig(all, initial, RigSolverOptions{}, &why);
  if (!outcome.joint) outcome.failure = "rig solve: " + why;
  return outcome;
}

void WriteRigResult(const std::filesystem::path& path, const RigOutcome& outcome) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  const RigSolution& joint = *outcome.joint;
  Json cameras = Json::object();
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const Mat6 covariance = joint.covariance.block<6, 6>(6 * c, 6 * c);
    const SolverResult& single = *outcome.single[c].solution;
    int pairs = 0;
    for (const PairFeatures& p : outcome.single[c].pairs)
      pairs += p.status == PairStatus::kAccepted;
    Json camera = PoseWithSigma(joint.cam_from_lidar[c], covariance);
    camera["cam_from_lidar"] = camera["matrix"];
    camera.erase("matrix");
    camera["covariance"] = Matrix6(covariance);
    camera["pairs"] = pairs;
    camera["single_camera"] = PoseWithSigma(single.cam_from_lidar, single.covariance);
    cameras[outcome.camera_names[c]] = camera;
  }
  Json relative = Json::object();
  for (size_t to = 1; to < outcome.camera_names.size(); ++to)
    for (size_t from = 0; from < to; ++from) {
      const RelativePose pose =
          CameraFromCamera(joint, static_cast<int>(to), static_cast<int>(from));
      relative[outcome.camera_names[to] + "_from_" + outcome.camera_names[from]] =
          PoseWithSigma(pose.to_from_from, pose.covariance);
    }
  const Json root = {{"format", "calibench.rig.v1"},
                     {"reference", "lidar"},
                     {"direction", "x_in_cam = cam_from_lidar * x_in_lidar"},
                     {"cameras", cameras},
                     {"camera_from_camera", relative},
                     {"captures", joint.used_captures},
                     {"shared_captures", outcome.shared_captures},
                     {"iterations", joint.iterations},
                     {"converged", joint.converged}};
  WriteFileAtomically(path, root.dump(2) + "\n");
}

std::vector<std::pair<std::string, Pose>> LoadRigResult(const std::filesystem::path& path) {
  std::ifstream file(path);
  if (!file) throw IoError(path.string() + ": cannot open the rig result");
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(file);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path.string() + ": not a valid rig result (JSON): " + e.what());
  }
  if (!root.is_object() || root.value("format", "") != "calibench.rig.v1" ||
      !root.contains("cameras") || !root["cameras"].is_object())
    throw IoError(path.string() + ": not a Calibench rig result (format calibench.rig.v1)");
  std::vector<std::pair<std::string, Pose>> cameras;
  for (const auto& [name, camera] : root["cameras"].items()) {
    const nlohmann::json& rows = camera["cam_from_lidar"];
    Pose pose = Pose::Identity();
    try {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = rows.at(r).at(c).get<double>();
    } catch (const nlohmann::json::exception&) {
      throw IoError(path.string() + ": cameras." + name + ".cam_from_lidar: not a 4x4 matrix");
    }
    cameras.emplace_back(name, pose);
  }
  if (cameras.empty()) throw IoError(path.string() + ": the rig result holds no camera");
  return cameras;
}

bool IsRigResultFile(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::string head(4096, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(file.gcount()));
  return head.find("calibench.rig.v1") != std::string::npos;
}

std::string FormatRigSummary(const RigOutcome& outcome) {
  std::string text;
  char line[512];
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const CalibrationOutcome& single = outcome.single[c];
    std::snprintf(line, sizeof(line), "camera %s:%s\n", outcome.camera_names[c].c_str(),
                  single.solution ? "" : (" no calibration: " + single.failure).c_str());
    text += line;
    if (!outcome.joint || !single.solution) continue;
    const Pose& pose = outcome.joint->cam_from_lidar[c];
    const Mat6 covariance = outcome.joint->covariance.block<6, 6>(6 * c, 6 * c);
    const Vec3 t = pose.translation(), st = 1e3 * TranslationStd(covariance, pose);
    const Vec3 sr = RotationStdDeg(covariance, pose);
    std::snprintf(line, sizeof(line),
                  "  cam_from_lidar t = [%.4f %.4f %.4f] m, σ t = [%.2f %.2f %.2f] mm, "
                  "σ r = [%.3f %.3f %.3f] deg (rig solve)\n",
                  t.x(), t.y(), t.z(), st.x(), st.y(), st.z(), sr.x(), sr.y(), sr.z());
    text += line;
    const Vec3 st1 =
        1e3 * TranslationStd(single.solution->covariance, single.solution->cam_from_lidar);
    const Vec3 sr1 = RotationStdDeg(single.solution->covariance, single.solution->cam_from_lidar);
    std::snprintf(line, sizeof(line),
                  "  alone: σ t = [%.2f %.2f %.2f] mm, σ r = [%.3f %.3f %.3f] deg\n", st1.x(),
                  st1.y(), st1.z(), sr1.x(), sr1.y(), sr1.z());
    text += line;
  }
  if (!outcome.joint) return text + "no rig solution: " + outcome.failure + "\n";
  for (size_t to = 1; to < outcome.camera_names.size(); ++to)
    for (size_t from = 0; from < to; ++from) {
      const RelativePose pose =
          CameraFromCamera(*outcome.joint, static_cast<int>(to), static_cast<int>(from));
      const Vec3 t = pose.to_from_from.translation();
      const Vec3 st = 1e3 * TranslationStd(pose.covariance, pose.to_from_from);
      const Vec3 sr = RotationStdDeg(pose.covariance, pose.to_from_from);
      std::snprintf(line, sizeof(line),
                    "%s_from_%s: t = [%.4f %.4f %.4f] m, σ t = [%.2f %.2f %.2f] mm, σ r = "
                    "[%.3f %.3f %.3f] deg (%d captures shared)\n",
                    outcome.camera_names[to].c_str(), outcome.camera_names[from].c_str(), t.x(),
                    t.y(), t.z(), st.x(), st.y(), st.z(), sr.x(), sr.y(), sr.z(),
                    outcome.shared_captures);
      text += line;
    }
  return text;
}

}  // namespace calibench
