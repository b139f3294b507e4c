// The panels below the views: the measurements list and the solver.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/lidar_camera/result_io.h"
#include "core/estimation/uncertainty.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"

namespace calibench::ui {
namespace {

constexpr ImGuiWindowFlags kPanelFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;

ImVec4 StatusColor(PairStatus status) {
  switch (status) {
    case PairStatus::kAccepted:
      return {0.45f, 0.85f, 0.45f, 1};
    case PairStatus::kRejected:
      return {0.95f, 0.65f, 0.3f, 1};
    case PairStatus::kFailed:
      return {1.0f, 0.4f, 0.35f, 1};
    case PairStatus::kPending:
      return {0.7f, 0.7f, 0.7f, 1};
  }
  return {1, 1, 1, 1};
}

void PrintPose(const char* name, const char* words, const Pose& pose) {
  ImGui::Text("%s", name);
  ImGui::SameLine();
  ImGui::TextDisabled("(%s)", words);
  for (int r = 0; r < 3; ++r)
    ImGui::Text("  % .5f % .5f % .5f | % .4f", pose.matrix()(r, 0), pose.matrix()(r, 1),
                pose.matrix()(r, 2), pose.matrix()(r, 3));
}

}  // namespace

void Workbench::MeasurementsPanel(const Snapshot& s, const ViewRect& r,
                                  std::vector<Intent>* intents) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  if (!ImGui::Begin("Measurements", nullptr, kPanelFlags)) return ImGui::End();
  if (s.loading_done < s.loading_total) {
    char label[64];
    std::snprintf(label, sizeof(label), "loading %d / %d pairs", s.loading_done, s.loading_total);
    ImGui::ProgressBar(static_cast<float>(s.loading_done) / std::max(1, s.loading_total), {-1, 0},
                       label);
  }
  const bool has_selection = s.selected >= 0;
  ImGui::BeginDisabled(!has_selection);
  if (ImGui::Button("Accept (A)"))
    intents->push_back(SetPairStatus{s.selected, PairStatus::kAccepted});
  ImGui::SameLine();
  if (ImGui::Button("Reject (R)"))
    intents->push_back(SetPairStatus{s.selected, PairStatus::kRejected});
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("arrows: previous / next   ctrl+z / ctrl+y: undo / redo");
  const float thumb_h = 36.0f;
  if (ImGui::BeginTable(
          "pairs", 6,
          ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_BordersInnerV,
          ImVec2(0, ImGui::GetContentRegionAvail().y))) {
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("image", ImGuiTableColumnFlags_WidthFixed, thumb_h * 4 / 3 + 4);
    ImGui::TableSetupColumn("pair", ImGuiTableColumnFlags_WidthFixed, 70);
    ImGui::TableSetupColumn("status", ImGuiTableColumnFlags_WidthFixed, 70);
    ImGui::TableSetupColumn("|e|", ImGuiTableColumnFlags_WidthFixed, 60);
    ImGui::TableSetupColumn("weight", ImGuiTableColumnFlags_WidthFixed, 50);
    ImGui::TableSetupColumn("details", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    for (int i = 0; i < static_cast<int>(s.pairs.size()); ++i) {
      const PairView& pair = s.pairs[i];
      ImGui::TableNextRow(0, thumb_h);
      ImGui::TableNextColumn();
      if (pair.thumbnail) {
        auto& texture = gl_->thumbnails[pair.id];
        if (!texture) {
          texture = std::make_unique<gfx::ImageTexture>();
          texture->Upload(*pair.thumbnail, true);
        }
        const float tw = thumb_h * pair.thumbnail->width / std::max(1, pair.thumbnail->height);
        ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture->texture())),
                     ImVec2(tw, thumb_h));
      }
      ImGui::TableNextColumn();
      ImGui::PushID(i);
      if (ImGui::Selectable(
              pair.id.c_str(), i == s.selected,
              ImGuiSelectableFlags_SpanAllColumns | ImGuiSelectableFlags_AllowItemOverlap,
              ImVec2(0, thumb_h)))
        intents->push_back(SelectPair{i});
      ImGui::PopID();
      ImGui::TableNextColumn();
      ImGui::TextColored(StatusColor(pair.status), "%s",
                         pair.loaded ? PairStatusName(pair.status).c_str() : "loading");
      ImGui::TableNextColumn();
      if (pair.residual) ImGui::Text("%.4f", pair.residual->norm());
      ImGui::TableNextColumn();
      if (pair.residual) {
        if (pair.robust_weight < 0.999)
          ImGui::TextColored({1.0f, 0.55f, 0.3f, 1}, "%.2f", pair.robust_weight);
        else
          ImGui::Text("%.2f", pair.robust_weight);
      }
      ImGui::TableNextColumn();
      if (!pair.reason.empty()) {
        ImGui::TextWrapped("%s", pair.reason.c_str());
      } else if (pair.lidar && pair.camera) {
        ImGui::TextDisabled("%zu inliers, %.1f mm | %d corners, %.2f px",
                            pair.lidar->inliers.size(), pair.lidar->rms_m * 1e3,
                            pair.camera->num_corners, pair.camera->reprojection_rms_px);
      }
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

void Workbench::SolverPanel(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  if (!ImGui::Begin("Solver", nullptr, kPanelFlags)) return ImGui::End();
  static constexpr SolverMethod kMethods[] = {SolverMethod::kWeightedMl, SolverMethod::kCa2libGn,
                                              SolverMethod::kKim};
  static constexpr const char* kMethodHelp[] = {
      "weighted-ml: both planes' covariances whiten the residual (default)",
      "ca2lib-gn: the paper's unweighted plane-to-plane Gauss-Newton",
      "kim: closed form from the normals (Kim et al. 2020), no refinement"};
  int method_index = 0;
  for (int i = 0; i < 3; ++i)
    if (kMethods[i] == s.method) method_index = i;
  double delta = s.huber_delta;
  int iterations = s.max_iterations;
  SolverMethod method = s.method;
  ImGui::SetNextItemWidth(140);
  if (ImGui::BeginCombo("method", SolverMethodName(s.method).c_str())) {
    for (int i = 0; i < 3; ++i) {
      if (ImGui::Selectable(SolverMethodName(kMethods[i]).c_str(), i == method_index))
        method = kMethods[i];
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", kMethodHelp[i]);
    }
    ImGui::EndCombo();
  }
  if (method != s.method)
    intents->push_back(SetSolverOptions{delta, iterations, method, s.estimate_range_offset});
  ImGui::SameLine();
  ImGui::BeginDisabled(s.method != SolverMethod::kWeightedMl);
  bool estimate_offset = s.estimate_range_offset;
  if (ImGui::Checkbox("range offset", &estimate_offset))
    intents->push_back(SetSolverOptions{delta, iterations, s.method, estimate_offset});
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
        "weighted-ml: also estimate a constant LiDAR range offset (measured = true + offset),\n"
        "reported with its standard deviation and its correlation with the translation");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("%s", kMethodHelp[method_index]);
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("Huber delta", &delta, 0.01, 0.1, "%.3f");
  const bool delta_done = ImGui::IsItemDeactivatedAfterEdit();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(100);
  ImGui::InputInt("max iterations", &iterations);
  if (delta_done || ImGui::IsItemDeactivatedAfterEdit())
    intents->push_back(SetSolverOptions{delta, iterations, s.method, s.estimate_range_offset});
  const bool solved = !s.solver.iterations.empty();
  ImGui::BeginDisabled(s.solver.running);
  if (ImGui::Button("Run (F5)")) {
    intents->push_back(RunSolver{});
    replay_position_ = -1;
    replaying_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Step")) {
    if (!solved) {
      intents->push_back(RunSolver{});
      replay_position_ = 0;
    } else {
      replay_position_ = replay_position_ < 0 ? 0 : replay_position_ + 1;
      if (replay_position_ >= static_cast<double>(s.solver.iterations.size()) - 1)
        replay_position_ = -1;
    }
    replaying_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Replay") && solved) {
    replay_position_ = 0;
    replaying_ = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("Reset")) {
    intents->push_back(ResetSolver{});
    replay_position_ = -1;
  }
  ImGui::EndDisabled();
  if (solved) {
    std::vector<float> log_cost;
    for (const IterationReport& it : s.solver.iterations)
      log_cost.push_back(static_cast<float>(std::log10(std::max(it.cost, 1e-30))));
    const int shown = replay_position_ < 0 ? static_cast<int>(log_cost.size()) - 1
                                           : static_cast<int>(replay_position_);
    char overlay[96];
    std::snprintf(overlay, sizeof(overlay), "log10 cost; iteration %d of %zu: %.4e", shown,
                  log_cost.size() - 1, s.solver.iterations[shown].cost);
    ImGui::PlotLines("##cost", log_cost.data(), static_cast<int>(log_cost.size()), 0, overlay,
                     FLT_MAX, FLT_MAX, ImVec2(r.w * 0.45f, 70));
    ImGui::SameLine();
    if (ImGui::BeginTable("iterations", 3, ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg,
                          ImVec2(0, 70))) {
      ImGui::TableSetupColumn("it");
      ImGui::TableSetupColumn("cost");
      ImGui::TableSetupColumn("|step|");
      ImGui::TableHeadersRow();
      for (const IterationReport& it : s.solver.iterations) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        if (it.iteration == shown)
          ImGui::TextColored({1, 0.85f, 0.3f, 1}, "%d", it.iteration);
        else
          ImGui::Text("%d", it.iteration);
        ImGui::TableNextColumn();
        ImGui::Text("%.4e", it.cost);
        ImGui::TableNextColumn();
        ImGui::Text("%.2e", it.step_norm);
      }
      ImGui::EndTable();
    }
  }
  if (!s.solver.failure.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.solver.failure.c_str());
  if (s.solver.result) {
    const SolverResult& res = *s.solver.result;
    // First, so that it is seen without scrolling: the estimate below leaves it out.
    if (res.unmodelled_range_offset)
      ImGui::TextColored({1.0f, 0.75f, 0.3f, 1},
                         "the data shows a LiDAR range offset of %+.1f ± %.1f mm that this solve "
                         "left out: tick \"range offset\" and solve again",
                         res.unmodelled_range_offset->value_m * 1e3,
                         res.unmodelled_range_offset->sigma_m * 1e3);
    PrintPose("cam_from_lidar", "x_cam = T * x_lidar", res.cam_from_lidar);
    PrintPose("lidar_from_cam", "camera position and axes in the LiDAR frame",
              res.cam_from_lidar.inverse());
    const Vec3 st = TranslationStd(res.covariance, res.cam_from_lidar) * 1000.0;
    const Vec3 sr = RotationStdDeg(res.covariance, res.cam_from_lidar);
    ImGui::Text("std (camera x/y/z): %.1f %.1f %.1f mm, %.3f %.3f %.3f deg", st.x(), st.y(), st.z(),
                sr.x(), sr.y(), sr.z());
    if (res.covariance_inflation > 1.0)
      ImGui::TextWrapped(
          "std widened by the spread over the pairs (variance x%.1f): the noise "
          "models underestimate this data",
          res.covariance_inflation);
    if (res.range_offset) {
      const Vec3& c = res.range_offset->correlation_with_translation;
      ImGui::Text("range offset: %+.1f ± %.1f mm (correlation with translation %.2f %.2f %.2f)",
                  res.range_offset->value_m * 1e3, res.range_offset->sigma_m * 1e3, c.x(), c.y(),
                  c.z());
    }
    if (res.edge_dilation) {
      ImGui::Text("board edges: %d crossings, sheet seen %+.1f ± %.1f mm larger per side",
                  res.num_edge_residuals, res.edge_dilation->value_m * 1e3,
                  res.edge_dilation->sigma_m * 1e3);
    }
    if (res.observability.well_constrained) {
      ImGui::TextColored({0.45f, 0.85f, 0.45f, 1}, "well constrained (%d iterations, %s)",
                         res.iterations, res.converged ? "converged" : "not converged");
    } else {
      ImGui::TextColored({1.0f, 0.45f, 0.3f, 1},
                         "NOT well constrained: add pairs with other board tilts");
      for (const std::string& d : res.observability.weak_directions)
        ImGui::TextColored({1.0f, 0.6f, 0.4f, 1}, "  weak: %s", d.c_str());
    }
    char path[512];
    std::snprintf(path, sizeof(path), "%s", export_path_.c_str());
    ImGui::SetNextItemWidth(220);
    if (ImGui::InputText("##export", path, sizeof(path))) export_path_ = path;
    ImGui::SameLine();
    if (ImGui::Button("Export result")) intents->push_back(ExportResult{export_path_});
  }
  char session[512];
  std::snprintf(session, sizeof(session), "%s", session_path_.c_str());
  ImGui::SetNextItemWidth(220);
  if (ImGui::InputText("##session", session, sizeof(session))) session_path_ = session;
  ImGui::SameLine();
  if (ImGui::Button("Save session as")) intents->push_back(SaveSessionAs{session_path_});
  ImGui::End();
}

}  // namespace calibench::ui
