// The 2D LRF workbench's state and the only place that changes it (the LRF counterpart of
// ui/lidar_camera/controller.h). Panels read an LrfSnapshot and return LrfIntents; the controller
// applies them and runs the LRF job (core/lrf/lrf_job.h, what `lrf-calibrate` runs: extraction
// and the solve) on a worker thread.
// No GL, GLFW or ImGui here: the controller is driven by tests without a window.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/base/image.h"
#include "core/lrf/lrf_job.h"
#include "core/lrf/pipeline.h"
#include "ui/state/controller_state.h"

namespace calibench::ui {

// Everything the panels show about one pair. The features are a shared, immutable buffer.
struct LrfPairView : PairHeader {
  bool extracted = false;
  std::shared_ptr<const LrfPairFeatures> features;
  // At the solver's estimate (after a solve): Eq. (12) mean corner-to-line distance (three-face
  // only) and the RMS point-to-plane distance of the pair's face / board scan points. Metres.
  std::optional<double> point_to_line_m;
  std::optional<double> point_to_plane_rms_m;
};

struct LrfSolverView {
  LrfMethod method = LrfMethod::kRefined;
  bool running = false;
  // Gauss-Newton iterations of the refined method (cost and cam_from_lrf in cam_from_lidar);
  // empty for paper-linear, which is closed form.
  std::vector<IterationReport> iterations;
  std::optional<LrfSolution> solution;  // ok solutions only; failures go to `failure`
  std::vector<std::string> solved_pair_ids;
  Vec3 std_translation_mm = Vec3::Zero();  // camera axes
  Vec3 std_rotation_deg = Vec3::Zero();    // camera axes
  std::string failure;
};

struct LrfSnapshot : SnapshotHeader {
  std::filesystem::path manifest;
  std::shared_ptr<const LrfDataset> dataset;  // null until a manifest opened
  std::vector<LrfPairView> pairs;
  int selected = -1;
  std::shared_ptr<const ImageU8> selected_image;  // checkerboard case: the RGB image of `selected`
  LrfSolverView solver;
  int extracted_done = 0, extracted_total = 0;
};

struct LrfSelectPair {
  int index;
};
struct LrfSetPairStatus {
  int index;
  PairStatus status;  // kAccepted or kRejected
};
struct LrfRunSolver {};
struct LrfResetSolver {};
struct LrfSetMethod {
  LrfMethod method;
};
struct LrfExportResult {
  std::filesystem::path path;  // a relative path is taken from the manifest's folder
};
using LrfIntent = std::variant<LrfSelectPair, LrfSetPairStatus, LrfRunSolver, LrfResetSolver,
                               LrfSetMethod, LrfExportResult>;

// Appends an intent constructed in place (a moved temporary variant trips GCC 12's
// -Wmaybe-uninitialized).
template <typename T, typename... Args>
void EmitLrfIntent(std::vector<LrfIntent>* intents, Args&&... args) {
  intents->emplace_back(std::in_place_type<T>, T{std::forward<Args>(args)...});
}

class LrfController : public ControllerState<LrfSnapshot> {
 public:
  explicit LrfController(LrfPipelineOptions options = {});
  ~LrfController();
  LrfController(const LrfController&) = delete;
  LrfController& operator=(const LrfController&) = delete;

  // Loads the manifest and queues feature extraction of every pair. A manifest that cannot be
  // read leaves the open dataset as it was and shows the error in the status line (false).
  bool Open(const std::filesystem::path& manifest);
  void Apply(const LrfIntent& intent);

 private:
  void OnJobError() override;
  // Pair `index` extracted by `job` (worker; the job of the Open that queued it).
  void Extract(LrfCalibrationJob* job, std::uint64_t open_count, int index);
  void Solve();
  void LoadSelectedImage();
  void UpdatePairFigures();  // call with mutex_ held
  bool ValidPair(int index) const;
  // One handler per intent type, as the lidar-camera controller has (Apply visits them with
  // mutex_ held and a dataset open).
  void Handle(const LrfSelectPair& intent);
  void Handle(const LrfSetPairStatus& intent);
  void Handle(const LrfRunSolver& intent);
  void Handle(const LrfResetSolver& intent);
  void Handle(const LrfSetMethod& intent);
  void Handle(const LrfExportResult& intent);

  LrfPipelineOptions options_;
  // The pipeline job over the open dataset (core/lrf/lrf_job.h), as `lrf-calibrate` runs it:
  // extraction and the solve, driven by the worker only; replaced by Open (mutex_ for the
  // pointer).
  std::shared_ptr<LrfCalibrationJob> job_;
  std::shared_ptr<const LrfCalibrationOutcome> outcome_;  // of the shown solution, for export
  std::uint64_t open_count_ = 0;  // a job of an earlier Open() discards its result
};

}  // namespace calibench::ui
