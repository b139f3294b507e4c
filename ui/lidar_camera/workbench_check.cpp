// The targetless check window (docs/targetless.md "Workbench"): check the workbench's calibration
// or a result file against the scenes of the loaded pairs without a board (RunCheck, the step
// `calibench check` runs); the verdict and why, the change and σ per camera axis, the cost along
// the weakest direction, the selected pair's image with its LiDAR edges under the calibration
// checked (red) and under the estimate (green), and "adopt the estimate" (undoable).
#include <imgui.h>

#include <algorithm>
#include <cstdio>

#include "core/targetless/check_overlay.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/path_field.h"

namespace calibench::ui {
namespace {

const ImVec4 kConsistent(0.45f, 0.85f, 0.45f, 1), kMiscalibrated(1.0f, 0.4f, 0.35f, 1),
    kCannotTell(1.0f, 0.72f, 0.3f, 1);

ImVec4 VerdictColor(CheckVerdict verdict) {
  switch (verdict) {
    case CheckVerdict::kConsistent:
      return kConsistent;
    case CheckVerdict::kMiscalibrated:
      return kMiscalibrated;
    case CheckVerdict::kRefined:  // a guess refined: a result, as a consistent check is
      return kConsistent;
    case CheckVerdict::kCannotTell:
      break;
  }
  return kCannotTell;
}

// Change and σ per camera axis (mm, degrees); an axis the scene cannot constrain in amber.
void AxesTable(const CheckReport& r) {
  if (!ImGui::BeginTable("check_axes", 4, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit))
    return;
  for (const char* header : {"camera axis", "change", "sigma", ""}) ImGui::TableSetupColumn(header);
  ImGui::TableHeadersRow();
  for (int axis = 0; axis < 6; ++axis) {
    const bool rotation = axis >= 3;
    const double change = rotation ? r.change_r_deg[axis - 3] : 1e3 * r.change_t_m[axis];
    const double sigma = rotation ? r.sigma_r_deg[axis - 3] : 1e3 * r.sigma_t_m[axis];
    const bool free = std::find(r.unconstrained_axes.begin(), r.unconstrained_axes.end(), axis) !=
                      r.unconstrained_axes.end();
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(CameraAxisName(axis).c_str());
    ImGui::TableNextColumn();
    ImGui::Text(rotation ? "%+.3f deg" : "%+.1f mm", change);
    ImGui::TableNextColumn();
    ImGui::Text(rotation ? "%.3f deg" : "%.1f mm", sigma);
    ImGui::TableNextColumn();
    if (free) ImGui::TextColored(kCannotTell, "the scene cannot tell");
  }
  ImGui::EndTable();
}

// The cost along the estimate's least constrained direction, ±2 tolerances about it: a clear
// minimum is a constrained check, a flat floor an axis the scene cannot tell.
void WeakestProfile(const CheckReport& r, float width) {
  if (r.weakest_costs.size() < 2) return;
  std::vector<float> costs(r.weakest_costs.begin(), r.weakest_costs.end());
  const auto [low, high] = std::minmax_element(costs.begin(), costs.end());
  ImGui::PlotLines("##weakest", costs.data(), static_cast<int>(costs.size()), 0,
                   "cost along the weakest direction", *low, *high + 1e-6f * (1 + *high),
                   ImVec2(width, 80));
  // The direction's largest component names it; one tolerance is the check's (RunCheck's options).
  int axis = 0;
  r.weakest_direction.cwiseAbs().maxCoeff(&axis);
  const CheckOptions options;
  ImGui::TextDisabled(
      "mostly %s; %.0f to %+.0f tolerances (one: %.2f deg / %.0f mm) about the "
      "estimate",
      CameraAxisName(axis).c_str(), r.weakest_offsets.front(), r.weakest_offsets.back(),
      options.tolerance_deg, 1e3 * options.tolerance_m);
}

}  // namespace

void Workbench::CheckWindow(const Snapshot& s, std::vector<Intent>* intents) {
  ImGui::SetNextWindowSize(ImVec2(720, 840), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Targetless check", &check_open_)) return ImGui::End();
  if (!s.dataset) {
    ImGui::TextDisabled("open a dataset first");
    return ImGui::End();
  }
  ImGui::TextWrapped(
      "Is the calibration still right? The scene's edges as the LiDAR (depth jumps, paint) and "
      "the camera see them, aligned around it in every pair's scene; no board is used.");
  ImGui::BeginDisabled(s.check.running || !s.solver.result);
  if (ImGui::Button("Check the workbench's calibration")) intents->push_back(RunCheck{});
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(s.check.running);
  if (PathField("##check_result", &check_result_path_, "Check this result file"))
    intents->push_back(RunCheck{check_result_path_});
  ImGui::EndDisabled();
  if (s.check.running) ImGui::TextDisabled("checking %s...", s.check.checked.c_str());
  if (!s.check.failure.empty()) ImGui::TextColored(kMiscalibrated, "%s", s.check.failure.c_str());
  if (!s.check.report) return ImGui::End();
  const CheckReport& r = *s.check.report;
  ImGui::Separator();
  ImGui::TextColored(VerdictColor(r.verdict), "%s", CheckVerdictName(r.verdict).c_str());
  ImGui::SameLine();
  ImGui::TextDisabled("%s, %d of %d frames used", s.check.checked.c_str(), r.frames_used,
                      r.frames_given);
  ImGui::PushTextWrapPos(0);
  ImGui::TextUnformatted(r.why.c_str());
  ImGui::PopTextWrapPos();
  for (const std::string& problem : s.check.unreadable)
    ImGui::TextColored(kCannotTell, "skipped %s", problem.c_str());
  ImGui::BeginDisabled(!r.has_estimate);
  if (ImGui::Button("Adopt the estimate")) intents->push_back(AdoptCheckEstimate{});
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
        "make the targetless estimate the workbench's calibration; its provenance says "
        "targetless, an export writes a targetless result, and Undo restores the one before");
  if (!s.solver.targetless_provenance.empty()) {
    ImGui::SameLine();
    ImGui::TextColored(kCannotTell, "the workbench's calibration is an adopted estimate");
  }
  if (r.has_estimate) {
    AxesTable(r);
    WeakestProfile(r, std::min(ImGui::GetContentRegionAvail().x, 680.0f));
  }
  CheckOverlay(s, r);
  ImGui::End();
}

void Workbench::CheckOverlay(const Snapshot& s, const CheckReport& r) {
  ImGui::Checkbox("red: the calibration checked", &check_show_reference_);
  ImGui::SameLine();
  ImGui::Checkbox("green: the estimate", &check_show_estimate_);
  if (s.selected < 0 || !s.selected_image || !s.check.lidar_edges) return;
  const std::string& id = s.pairs[static_cast<size_t>(s.selected)].id;
  const auto edges = s.check.lidar_edges->find(id);
  if (edges == s.check.lidar_edges->end() || s.selected_image_pair != id) {
    ImGui::TextDisabled("pair %s: no scene edges (its frame was not read)", id.c_str());
    return;
  }
  // Drawn again only when the report, the pair or the choices change.
  char key[160];
  std::snprintf(key, sizeof(key), "%p %s %p %d %d", static_cast<const void*>(&r), id.c_str(),
                static_cast<const void*>(s.selected_image.get()), check_show_reference_,
                check_show_estimate_ && r.has_estimate);
  if (check_overlay_key_ != key) {
    std::vector<OverlayPose> poses;
    if (check_show_reference_) poses.push_back({r.reference, 40, 40, 255});
    if (check_show_estimate_ && r.has_estimate) poses.push_back({r.estimate, 60, 255, 60});
    gl_->check_overlay.Upload(
        DrawEdgeOverlay(*s.selected_image, edges->second, s.dataset->camera, poses));
    check_overlay_key_ = key;
  }
  // The picture fits what is left of the window, at the image's aspect.
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float aspect = static_cast<float>(gl_->check_overlay.height()) /
                       static_cast<float>(std::max(1, gl_->check_overlay.width()));
  const float room = std::max(120.0f, avail.y - ImGui::GetTextLineHeightWithSpacing());
  const float width = std::min({avail.x, 680.0f, room / aspect});
  const float height = width * aspect;
  ImGui::Image(TextureId(gl_->check_overlay.texture()), ImVec2(width, height));
  ImGui::TextDisabled("pair %s: %zu LiDAR edge points (select another pair in the list)",
                      id.c_str(), edges->second.size());
}

}  // namespace calibench::ui
