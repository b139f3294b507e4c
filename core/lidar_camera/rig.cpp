#include "core/lidar_camera/rig.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/estimation/uncertainty.h"
#include "core/io/json_fields.h"
#include "core/io/json_io.h"

namespace calibench {
namespace {

using Json = nlohmann::ordered_json;

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

// The pose (under `key`) with its σ in its own axes (translation mm, rotation deg).
Json PoseWithSigma(const char* key, const Pose& pose, const Mat6& covariance) {
  return {{key, json_io::MatrixToJson(pose.matrix())},
          {"sigma_translation_mm", Vector3(1e3 * TranslationStd(covariance, pose))},
          {"sigma_rotation_deg", Vector3(RotationStdDeg(covariance, pose))}};
}

// "σ t = [..] mm, σ r = [..] deg" of the pose in its own axes.
std::string SigmaText(const Pose& pose, const Mat6& covariance) {
  const Vec3 st = 1e3 * TranslationStd(covariance, pose), sr = RotationStdDeg(covariance, pose);
  char text[128];
  std::snprintf(text, sizeof(text), "σ t = [%.2f %.2f %.2f] mm, σ r = [%.3f %.3f %.3f] deg", st.x(),
                st.y(), st.z(), sr.x(), sr.y(), sr.z());
  return text;
}

std::string TranslationText(const Pose& pose) {
  char text[96];
  std::snprintf(text, sizeof(text), "t = [%.4f %.4f %.4f] m", pose.translation().x(),
                pose.translation().y(), pose.translation().z());
  return text;
}

}  // namespace

RigCalibration::RigCalibration(RigFolder rig, PipelineOptions options, RigEdits edits,
                               ProgressCallback progress, size_t pairs_per_thread)
    : rig_(std::move(rig)),
      options_(std::move(options)),
      edits_(std::move(edits)),
      progress_(std::move(progress)),
      pairs_per_thread_(pairs_per_thread) {
  outcome_.camera_names = rig_.camera_names;
}

RigCalibration::~RigCalibration() = default;

bool RigCalibration::Step() {
  if (solved_) return false;
  if (next_camera_ < rig_.cameras.size()) {
    // Each camera's own calibration (with the LiDAR's planes, the board's edges, the range
    // offset and its honest σ) is its prior; the boards two cameras saw at once tie the cameras
    // to each other on top of it (SolveRigFromCameras).
    const size_t c = next_camera_;
    if (!camera_) {
      const auto camera_edits = edits_.find(rig_.camera_names[c]);
      camera_ = std::make_unique<DatasetCalibration>(
          rig_.cameras[c], options_,
          camera_edits == edits_.end() ? PairEdits{} : camera_edits->second, progress_,
          pairs_per_thread_);
    }
    if (camera_->Step()) return true;
    CalibrationOutcome single = camera_->Take();
    camera_.reset();
    ++next_camera_;
    FinishCamera(c, std::move(single));
    return true;
  }
  solved_ = true;
  if (!outcome_.failure.empty()) return false;
  if (!outcome_.Several()) {  // nothing to tie: the camera's own solve is the rig's
    outcome_ = RigOutcomeOfOne(rig_, std::move(outcome_.single.front()));
    return false;
  }
  std::vector<RigCapture> all;
  for (auto& [stem, capture] : captures_) all.push_back(std::move(capture));
  std::string why;
  outcome_.joint =
      SolveRigFromCameras(all, priors_, RigSolverOptions{}, &why, &outcome_.shared_captures);
  if (!outcome_.joint) outcome_.failure = "rig solve: " + why;
  return false;
}

void RigCalibration::FinishCamera(size_t c, CalibrationOutcome single_outcome) {
  outcome_.single.push_back(std::move(single_outcome));
  const CalibrationOutcome& single = outcome_.single.back();
  if (!single.solution) {
    outcome_.failure = "camera '" + rig_.camera_names[c] + "': " + single.failure;
    return;
  }
  priors_.push_back({single.solution->cam_from_lidar, single.solution->covariance});
  for (const PairFeatures& pair : single.pairs) {
    if (pair.status != PairStatus::kAccepted || !pair.lidar || !pair.camera) continue;
    RigCapture& capture = captures_[pair.id];
    capture.id = pair.id;
    capture.views.push_back(
        {static_cast<int>(c), pair.camera->cam_from_board, pair.camera->pose_covariance});
  }
}

RigOutcome RigOutcomeOfOne(const RigFolder& rig, CalibrationOutcome single) {
  CALIBENCH_CHECK(rig.camera_names.size() == 1);
  RigOutcome outcome;
  outcome.camera_names = rig.camera_names;
  outcome.single.push_back(std::move(single));
  const CalibrationOutcome& camera = outcome.single.front();
  if (!camera.solution) {
    outcome.failure = "camera '" + rig.camera_names.front() + "': " + camera.failure;
    return outcome;
  }
  RigSolution joint;
  joint.cam_from_lidar = {camera.solution->cam_from_lidar};
  joint.covariance = camera.solution->covariance;
  joint.converged = true;
  joint.used_captures = AcceptedPairs(camera);
  outcome.joint = std::move(joint);
  return outcome;
}

RigOutcome CalibrateRig(const RigFolder& rig, const PipelineOptions& options,
                        const ProgressCallback& progress, const RigEdits& edits) {
  RigCalibration calibration(rig, options, edits, progress);
  while (calibration.Step()) {
  }
  return calibration.Outcome();
}

PoseWithSigmas RigJointPose(const RigOutcome& outcome, size_t c) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  const Pose& pose = outcome.joint->cam_from_lidar[c];
  const Mat6 covariance = outcome.joint->covariance.block<6, 6>(6 * c, 6 * c);
  return {outcome.camera_names[c], pose, 1e3 * TranslationStd(covariance, pose),
          RotationStdDeg(covariance, pose)};
}

std::vector<PoseWithSigmas> RigRelativePoses(const RigOutcome& outcome) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  std::vector<PoseWithSigmas> relative;
  for (size_t to = 1; to < outcome.camera_names.size(); ++to) {
    const RelativePose pose = CameraFromCamera(*outcome.joint, static_cast<int>(to), 0);
    relative.push_back({outcome.camera_names[to] + "_from_" + outcome.camera_names[0],
                        pose.to_from_from, 1e3 * TranslationStd(pose.covariance, pose.to_from_from),
                        RotationStdDeg(pose.covariance, pose.to_from_from)});
  }
  return relative;
}

void WriteRigResult(const std::filesystem::path& path, const RigOutcome& outcome) {
  CALIBENCH_CHECK(outcome.joint.has_value());
  const RigSolution& joint = *outcome.joint;
  Json cameras = Json::object();
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const Mat6 covariance = joint.covariance.block<6, 6>(6 * c, 6 * c);
    const SolverResult& single = *outcome.single[c].solution;
    Json camera = PoseWithSigma("cam_from_lidar", joint.cam_from_lidar[c], covariance);
    camera["covariance"] = Matrix6(covariance);
    camera["pairs"] = AcceptedPairs(outcome.single[c]);
    camera["single_camera"] = PoseWithSigma("matrix", single.cam_from_lidar, single.covariance);
    cameras[outcome.camera_names[c]] = camera;
  }
  Json relative = Json::object();
  for (size_t to = 1; to < outcome.camera_names.size(); ++to)
    for (size_t from = 0; from < to; ++from) {
      const RelativePose pose =
          CameraFromCamera(joint, static_cast<int>(to), static_cast<int>(from));
      relative[outcome.camera_names[to] + "_from_" + outcome.camera_names[from]] =
          PoseWithSigma("matrix", pose.to_from_from, pose.covariance);
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
  const nlohmann::json root = json_io::ReadJson(path);
  const json_io::Fields fields(root, path);
  json_io::CheckFormat(fields, "calibench.rig.v1");
  fields.Object("cameras");  // an object, else the error names it
  std::vector<std::pair<std::string, Pose>> poses;
  for (const auto& [name, camera] : fields.At("cameras").items()) {
    const json_io::Fields entry(camera, path, "cameras." + name);
    poses.emplace_back(name, json_io::PoseFromJson(entry.At("cam_from_lidar"), path,
                                                   entry.Path("cam_from_lidar")));
  }
  if (poses.empty()) throw IoError(path.string() + ": the rig result holds no camera");
  // The writer's order (the folder's natural order), not the parser's alphabetical one.
  std::sort(poses.begin(), poses.end(),
            [](const auto& a, const auto& b) { return NaturalOrder{}(a.first, b.first); });
  return poses;
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
  for (size_t c = 0; c < outcome.camera_names.size(); ++c) {
    const CalibrationOutcome& single = outcome.single[c];
    text += "camera " + outcome.camera_names[c] + ":" +
            (single.solution ? "" : " no calibration: " + single.failure) + "\n";
    if (!outcome.joint || !single.solution) continue;
    const Pose& pose = outcome.joint->cam_from_lidar[c];
    text += "  cam_from_lidar " + TranslationText(pose) + ", " +
            SigmaText(pose, outcome.joint->covariance.block<6, 6>(6 * c, 6 * c)) + " (rig solve)\n";
    text += "  alone: " + SigmaText(single.solution->cam_from_lidar, single.solution->covariance) +
            "\n";
  }
  if (!outcome.joint) return text + "no rig solution: " + outcome.failure + "\n";
  for (size_t to = 1; to < outcome.camera_names.size(); ++to)
    for (size_t from = 0; from < to; ++from) {
      const RelativePose pose =
          CameraFromCamera(*outcome.joint, static_cast<int>(to), static_cast<int>(from));
      text += outcome.camera_names[to] + "_from_" + outcome.camera_names[from] + ": " +
              TranslationText(pose.to_from_from) + ", " +
              SigmaText(pose.to_from_from, pose.covariance) + " (" +
              std::to_string(outcome.shared_captures) + " captures shared)\n";
    }
  return text;
}

}  // namespace calibench
