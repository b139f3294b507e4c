// The LRF workbench's panels: the measurements table (one row per pair), the solver and its
// solution, and the keys.
#include <imgui.h>

#include <cstdio>
#include <optional>

#include "core/lrf/result_io.h"
#include "ui/lrf/workbench.h"
#include "ui/widgets/pair_review.h"
#include "ui/widgets/path_field.h"
#include "ui/widgets/solution_readouts.h"

namespace calibench::ui {
namespace {

void TextMm(const std::optional<double>& metres) {
  if (metres) ImGui::Text("%.1f", *metres * 1e3);
}

// Id (selects the pair), status, scan and depth (or PnP) RMS, Eq. 12 and plane residuals (mm),
// what the pair gave.
void PairRow(const LrfSnapshot& s, int index, std::vector<LrfIntent>* intents) {
  const LrfPairView& pair = s.pairs[index];
  const LrfPairFeatures* f = pair.features.get();
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  if (PairSelectable(index, pair.id, index == s.selected))
    EmitLrfIntent<LrfSelectPair>(intents, index);
  ImGui::TableNextColumn();
  PairStatusText(pair.status, pair.extracted ? PairStatusName(pair.status) : "extracting");
  ImGui::TableNextColumn();
  if (f && f->three_face && f->three_face->scan.ok) TextMm(f->three_face->scan.rms_m);
  if (f && f->board_scan && f->board_scan->ok) TextMm(f->board_scan->rms_m);
  ImGui::TableNextColumn();
  if (f && f->three_face && f->three_face->depth.ok) TextMm(f->three_face->depth.rms_m);
  if (f && f->camera) ImGui::Text("%.2f", f->camera->reprojection_rms_px);
  ImGui::TableNextColumn();
  TextMm(pair.point_to_line_m);
  ImGui::TableNextColumn();
  TextMm(pair.point_to_plane_rms_m);
  ImGui::TableNextColumn();
  if (!pair.reason.empty())
    ImGui::TextWrapped("%s", pair.reason.c_str());
  else if (f && f->three_face)
    ImGui::TextDisabled(
        "%zu scan points, faces %d / %d / %d px", f->three_face->scan.target_indices.size(),
        f->three_face->depth.inlier_counts[0], f->three_face->depth.inlier_counts[1],
        f->three_face->depth.inlier_counts[2]);
  else if (f && f->board_scan && f->camera)
    ImGui::TextDisabled("%zu board points, %d corners", f->board_scan->points.size(),
                        f->camera->num_corners);
}

}  // namespace

void LrfWorkbench::MeasurementsPanel(const LrfSnapshot& s, const Rect& r,
                                     std::vector<LrfIntent>* intents) {
  if (!BeginPanel("Measurements", r)) return ImGui::End();
  PairProgress("extracting", s.extracted_done, s.extracted_total);
  if (const auto status = ReviewButtons(s.selected >= 0, "arrows: previous / next; figures in mm"))
    EmitLrfIntent<LrfSetPairStatus>(intents, s.selected, *status);
  const bool board_case = s.dataset && s.dataset->target_type == LrfTargetType::kCheckerboard;
  if (BeginPairsTable({{"pair", 60},
                       {"status", 70},
                       {"scan", 45},
                       {board_case ? "PnP px" : "depth", 50},
                       {"Eq.12", 50},
                       {"plane", 45},
                       {"details"}})) {
    for (int i = 0; i < static_cast<int>(s.pairs.size()); ++i) PairRow(s, i, intents);
    ImGui::EndTable();
  }
  ImGui::End();
}

void LrfWorkbench::SolverPanel(const LrfSnapshot& s, const Rect& r,
                               std::vector<LrfIntent>* intents) {
  if (!BeginPanel("Solver", r)) return ImGui::End();
  static const char* kMethods[] = {"paper-linear (Eq. 9-11)", "refined (point-to-plane GN)"};
  int method = s.solver.method == LrfMethod::kPaperLinear ? 0 : 1;
  ImGui::SetNextItemWidth(230);
  if (ImGui::Combo("method", &method, kMethods, 2))
    EmitLrfIntent<LrfSetMethod>(intents,
                                method == 0 ? LrfMethod::kPaperLinear : LrfMethod::kRefined);
  const SolverReplay::Request request =
      replay().Buttons(s.solver.iterations.size(), s.solver.running);
  if (request.run) EmitLrfIntent<LrfRunSolver>(intents);
  if (request.reset) EmitLrfIntent<LrfResetSolver>(intents);
  if (s.solver.running) {
    ImGui::SameLine();
    ImGui::TextColored({0.95f, 0.8f, 0.3f, 1}, "solving ...");
  }
  if (!s.solver.iterations.empty())
    replay().CostPlot(s.solver.iterations, ImVec2(r.w * 0.55f, 60));
  else if (s.solver.solution)
    ImGui::TextDisabled("closed form (Eq. 11): no iterations to replay");
  if (!s.solver.failure.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.solver.failure.c_str());
  if (s.solver.solution) SolutionReadouts(s, intents);
  ImGui::End();
}

void LrfWorkbench::SolutionReadouts(const LrfSnapshot& s, std::vector<LrfIntent>* intents) {
  const LrfSolution& solution = *s.solver.solution;
  const Pose& pose = solution.cam_from_lrf;
  PoseReadout("cam_from_lrf", "x_cam = cam_from_lrf * x_lrf", pose);
  StdReadout(s.solver.std_translation_mm, s.solver.std_rotation_deg);
  ImGui::Text(
      "%s over %zu pairs",
      LrfResidualText(solution, s.dataset ? s.dataset->target_type : LrfTargetType::kThreeFace)
          .c_str(),
      s.solver.solved_pair_ids.size());
  if (s.dataset && s.dataset->cam_from_lrf_ground_truth) {
    const Pose& truth = *s.dataset->cam_from_lrf_ground_truth;
    ImGui::TextDisabled("vs ground truth: %.1f mm, %.3f deg",
                        (pose.translation() - truth.translation()).norm() * 1e3,
                        RotationAngle(pose.linear(), truth.linear()) * kRadToDeg);
  }
  const char* convergence = solution.method != LrfMethod::kRefined ? ""
                            : solution.converged                   ? ", converged"
                                                                   : ", not converged";
  ObservabilityReadout(solution.observability,
                       LrfMethodName(solution.method) + ", " + std::to_string(solution.iterations) +
                           " iterations" + convergence,
                       "NOT well constrained: add observations with other target poses");
  if (PathField("##export", &export_path_, "Export result"))
    EmitLrfIntent<LrfExportResult>(intents, export_path_);
}

void LrfWorkbench::HandleKeys(const LrfSnapshot& s, std::vector<LrfIntent>* intents) {
  if (ImGui::GetIO().WantTextInput || s.selected < 0) return;
  const int n = static_cast<int>(s.pairs.size());
  const ReviewKeys keys = ReadReviewKeys();
  if (keys.accept) EmitLrfIntent<LrfSetPairStatus>(intents, s.selected, PairStatus::kAccepted);
  if (keys.reject) EmitLrfIntent<LrfSetPairStatus>(intents, s.selected, PairStatus::kRejected);
  if (keys.next) EmitLrfIntent<LrfSelectPair>(intents, std::min(n - 1, s.selected + 1));
  if (keys.previous) EmitLrfIntent<LrfSelectPair>(intents, std::max(0, s.selected - 1));
  if (keys.run) EmitLrfIntent<LrfRunSolver>(intents);
  const bool ctrl = ImGui::GetIO().KeyCtrl;
  if (ctrl && KeyPressed('Z')) EmitLrfIntent<LrfUndo>(intents);
  if (ctrl && KeyPressed('Y')) EmitLrfIntent<LrfRedo>(intents);
}

}  // namespace calibench::ui
