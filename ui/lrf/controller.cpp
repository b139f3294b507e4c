#include "ui/lrf/controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/estimation/uncertainty.h"
#include "core/io/image_io.h"
#include "core/lrf/result_io.h"

namespace calibench::ui {
namespace {

// Both sides of the pair gave what the solver needs.
bool HasFeatures(const LrfPairFeatures& features) {
  if (features.three_face) return features.three_face->scan.ok && features.three_face->depth.ok;
  return features.board_scan && features.board_scan->ok && features.camera.has_value();
}

std::string FeatureFailure(const LrfPairFeatures& features) {
  if (!features.reason.empty()) return features.reason;
  if (features.three_face) {
    if (!features.three_face->scan.ok) return "scan: " + features.three_face->scan.reason;
    if (!features.three_face->depth.ok) return "depth: " + features.three_face->depth.reason;
  }
  if (features.board_scan && !features.board_scan->ok)
    return "scan: " + features.board_scan->reason;
  if (!features.camera) return "camera: no board pose";
  return "no features";
}

// RMS distance of the pair's scan points, moved into the camera frame, to their planes.
double PointToPlaneRms(const LrfPairFeatures& features, const Pose& cam_from_lrf) {
  double sum = 0.0;
  size_t count = 0;
  auto add = [&](const Vec2& point, const Plane& plane) {
    const double r = plane.SignedDistance(cam_from_lrf * Vec3(point.x(), point.y(), 0.0));
    sum += r * r;
    ++count;
  };
  if (features.three_face) {
    for (int face = 0; face < 3; ++face)
      for (const Vec2& p : features.three_face->scan.face_points[face])
        add(p, features.three_face->depth.planes[face]);
  } else if (features.board_scan && features.camera) {
    for (const Vec2& p : features.board_scan->points) add(p, features.camera->plane);
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

}  // namespace

LrfController::LrfController(LrfPipelineOptions options)
    : options_(std::move(options)), session_(Host()) {
  state_.solver.method = options_.solver.method;
  state_.status_line = "open an LRF dataset manifest";
}

LrfController::~LrfController() { StopWorker(); }

void LrfController::OnJobError() { state_.solver.running = false; }

void LrfController::Extract(LrfCalibrationJob* job, std::uint64_t open_count, int index) {
  {
    std::lock_guard lock(mutex_);
    if (open_count != open_count_) return;
  }
  const std::shared_ptr<const LrfPairFeatures> features = job->ExtractPair(index);
  std::lock_guard lock(mutex_);
  if (open_count != open_count_) return;
  LrfPairView& pair = state_.pairs.Edit(index);
  pair.features = features;
  pair.extracted = true;
  Restatus();
  if (++state_.extracted_done == state_.extracted_total) {
    const int accepted = static_cast<int>(
        std::count_if(state_.pairs.begin(), state_.pairs.end(),
                      [](const LrfPairView& p) { return p.status == PairStatus::kAccepted; }));
    SetStatus("extracted " + std::to_string(state_.extracted_total) +
                  " pairs: " + std::to_string(accepted) + " accepted, " +
                  std::to_string(state_.extracted_total - accepted) + " not",
              false);
  } else {
    ++state_.generation;
  }
}

void LrfController::Solve() {
  std::shared_ptr<LrfCalibrationJob> job;
  {
    std::lock_guard lock(mutex_);
    if (!state_.dataset || !job_) return;
    job = job_;
    const LrfMethod method = state_.solver.method;
    state_.solver = LrfSolverView{};
    state_.solver.method = method;
    state_.solver.running = true;
    outcome_.reset();
    UpdatePairFigures();
    SetStatus("solving (" + LrfMethodName(method) + ") ...", false);
  }
  // The job reads the user's rejections and method from its record, where the intents put them.
  auto outcome = std::make_shared<LrfCalibrationOutcome>(job->Solve());
  std::lock_guard lock(mutex_);
  if (job != job_) return;  // another dataset opened while it solved
  session_.Edited();        // the solve is the record's now
  LrfSolverView& solver = state_.solver;
  solver.running = false;
  if (!outcome->solution || !outcome->solution->ok) {
    solver.failure = !outcome->failure.empty() ? outcome->failure
                     : outcome->solution       ? outcome->solution->reason
                                               : "no calibration";
    SetStatus("no calibration: " + solver.failure, true);
    return;
  }
  const LrfSolution& solution = *outcome->solution;
  solver.solution = solution;
  // The refinement's recorded iterations drive the cost plot, Step and Replay.
  solver.iterations = solution.history;
  for (const LrfPairFeatures& p : outcome->pairs)
    if (p.status == PairStatus::kAccepted) solver.solved_pair_ids.push_back(p.id);
  solver.std_translation_mm = TranslationStd(solution.covariance, solution.cam_from_lrf) * 1e3;
  solver.std_rotation_deg = RotationStdDeg(solution.covariance, solution.cam_from_lrf);
  outcome_ = outcome;
  UpdatePairFigures();
  const bool well = solution.observability.well_constrained;
  char line[256];
  std::snprintf(line, sizeof(line), "solved (%s) with %zu pairs: %s%s",
                LrfMethodName(solution.method).c_str(), solver.solved_pair_ids.size(),
                LrfResidualText(solution, state_.dataset ? state_.dataset->target_type
                                                         : LrfTargetType::kThreeFace)
                    .c_str(),
                well ? "" : " (NOT well constrained)");
  SetStatus(line, !well);
}

void LrfController::Restatus() {
  mutex_.AssertHeld(__func__);
  for (LrfPairView& pair : state_.pairs.Edit()) {
    if (job_->record().Rejected(pair.id, &pair.reason)) {
      pair.status = PairStatus::kRejected;
    } else if (!pair.features) {
      pair.status = PairStatus::kPending;
      pair.reason.clear();
    } else {
      const bool usable = HasFeatures(*pair.features);
      pair.status = usable ? PairStatus::kAccepted : PairStatus::kFailed;
      pair.reason = usable ? "" : FeatureFailure(*pair.features);
    }
  }
  ++state_.generation;
}

void LrfController::UpdatePairFigures() {
  mutex_.AssertHeld(__func__);
  const LrfSolution* solution = state_.solver.solution ? &*state_.solver.solution : nullptr;
  for (LrfPairView& pair : state_.pairs.Edit()) {
    pair.point_to_line_m.reset();
    pair.point_to_plane_rms_m.reset();
    if (!solution || !pair.features || !HasFeatures(*pair.features)) continue;
    if (pair.features->three_face)
      pair.point_to_line_m = PointToLineError(*pair.features->three_face, solution->cam_from_lrf);
    pair.point_to_plane_rms_m = PointToPlaneRms(*pair.features, solution->cam_from_lrf);
  }
  ++state_.generation;
}

void LrfController::LoadSelectedImage() {
  std::filesystem::path path;
  const std::shared_ptr<const ImageU8> image = LoadSelectedImageFile(&path);
  if (!image) return;
  std::lock_guard lock(mutex_);
  if (!StillSelected(state_, path)) return;
  state_.selected_image = image;
  ++state_.generation;
}

void LrfController::Apply(const LrfIntent& intent) {
  std::lock_guard lock(mutex_);
  if (!state_.dataset) return;
  std::visit([this](const auto& what) { Handle(what); }, intent);
}

bool LrfController::ValidPair(int index) const {
  return index >= 0 && index < static_cast<int>(state_.pairs.size());
}

void LrfController::Handle(const LrfSelectPair& select) {
  if (!ValidPair(select.index) || select.index == state_.selected) return;
  state_.selected = select.index;
  state_.selected_image.reset();
  ++state_.generation;
  // Saved with the session, but no undo step (as in the LiDAR-camera workbench).
  const std::string view =
      nlohmann::json{{"selected_pair", state_.pairs.at(select.index).id}}.dump();
  job_->record().Edit([&](Session* session) { session->view_json = view; }, /*amend=*/true);
  session_.Autosave();
  if (state_.dataset->target_type == LrfTargetType::kCheckerboard)
    worker_.Enqueue([this] { LoadSelectedImage(); });
}

void LrfController::Handle(const LrfSetPairStatus& status) {
  if (!ValidPair(status.index)) return;
  LrfPairView& pair = state_.pairs.Edit(status.index);
  if (status.status == PairStatus::kAccepted && !(pair.features && HasFeatures(*pair.features))) {
    SetStatus("pair " + pair.id + " cannot be accepted: " +
                  (pair.features ? FeatureFailure(*pair.features) : "features not extracted yet"),
              true);
    return;
  }
  job_->SetRejected(pair.id, status.status == PairStatus::kRejected);
  Restatus();
  session_.Edited();
  SetStatus("pair " + pair.id + " " + PairStatusName(pair.status) +
                (state_.solver.solution ? "; press Run to re-solve" : ""),
            false);
}

void LrfController::Handle(const LrfRunSolver&) {
  if (state_.solver.running) return;
  state_.solver.running = true;  // until the queued solve starts and reports
  ++state_.generation;
  worker_.Enqueue([this] { Solve(); });
}

void LrfController::Handle(const LrfResetSolver&) {
  const LrfMethod method = state_.solver.method;
  state_.solver = LrfSolverView{};
  state_.solver.method = method;
  outcome_.reset();
  UpdatePairFigures();
  job_->record().Edit([](Session* session) { session->result.reset(); }, /*amend=*/true);
  session_.Edited();
}

void LrfController::Handle(const LrfSetMethod& method) {
  if (method.method == state_.solver.method) return;
  state_.solver.method = method.method;
  job_->SetMethod(method.method);
  session_.Edited();
  SetStatus("method " + LrfMethodName(method.method) + "; press Run to solve with it", false);
}

void LrfController::Handle(const LrfExportResult& export_result) {
  if (!outcome_ || !outcome_->solution) {
    SetStatus("nothing to export: run the solver first", true);
    return;
  }
  LrfPipelineOptions options = options_;
  options.solver.method = outcome_->solution->method;
  // A relative path goes beside the manifest, as the lidar-camera exports go beside the session:
  // not into wherever the program happened to be started.
  std::filesystem::path path = export_result.path;
  if (path.is_relative() && !state_.manifest.empty()) path = state_.manifest.parent_path() / path;
  try {
    WriteLrfResult(path, *outcome_, options);
    SetStatus("exported " + path.string(), false);
  } catch (const IoError& e) {
    SetStatus(e.what(), true);
  }
}

}  // namespace calibench::ui
