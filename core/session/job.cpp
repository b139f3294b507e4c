#include "core/session/job.h"

#include "core/io/dataset_source.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/session/lrf_calibration_job.h"

namespace calibench {

std::string JobKindName(JobKind kind) { return kind == JobKind::kLrf ? "2D LRF" : "LiDAR-camera"; }

JobKind JobKindOf(const std::filesystem::path& dataset, const std::filesystem::path& session) {
  if (!session.empty()) return IsLrfSession(session) ? JobKind::kLrf : JobKind::kLidarCamera;
  if (dataset.empty()) return JobKind::kLidarCamera;
  std::string ignored;  // a dataset nothing recognises is the LiDAR-camera reader's to name
  const std::optional<DatasetSource> source = RecogniseDataset(dataset, &ignored);
  return source && source->kind == DatasetKind::kLrf ? JobKind::kLrf : JobKind::kLidarCamera;
}

bool JobVerdict::input_error() const {
  for (const JobPair& pair : pairs)
    if (pair.input_error) return true;
  return false;
}

std::string JobVerdict::Unreadable(const std::string& camera) const {
  std::string lines;
  for (const JobPair& pair : pairs)
    if (pair.input_error) lines += "\n  " + camera + "pair " + pair.id + ": " + pair.reason;
  return lines;
}

std::vector<JobVerdict> CameraVerdicts(const RigFolder& rig, const RigOutcome& outcome) {
  CALIBENCH_CHECK(rig.cameras.size() == outcome.camera_names.size());
  std::vector<JobVerdict> verdicts;
  for (size_t c = 0; c < outcome.single.size(); ++c) {
    const CalibrationOutcome& single = outcome.single[c];
    JobVerdict verdict = VerdictOf(
        single, [](const SolverResult& solution) { return solution.cam_from_lidar; }, "",
        rig.cameras[c].cam_from_lidar_ground_truth);
    verdict.solved = outcome.joint.has_value();
    verdict.failure = outcome.joint ? "" : outcome.failure;
    if (outcome.joint) {
      verdict.cam_from_source = outcome.joint->cam_from_lidar[c];
      verdict.covariance = outcome.joint->covariance.block<6, 6>(6 * c, 6 * c);
    }
    verdicts.push_back(std::move(verdict));
  }
  return verdicts;
}

}  // namespace calibench
