#include "core/session/job.h"

#include "core/io/dataset_source.h"
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

std::string JobVerdict::Unreadable() const {
  std::string lines;
  for (const JobPair& pair : pairs)
    if (pair.input_error) lines += "\n  pair " + pair.id + ": " + pair.reason;
  return lines;
}

}  // namespace calibench
