#include "ui/widgets/solver_replay.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>

namespace calibench::ui {

void SolverReplay::Advance(size_t iterations, double seconds_since_last_frame) {
  if (!playing_ || iterations == 0) return;
  position_ = std::max(0.0, position_) + 2.0 * seconds_since_last_frame;  // 2 it/s
  if (position_ >= static_cast<double>(iterations) - 1) {
    position_ = -1;
    playing_ = false;
  }
}

int SolverReplay::Shown(size_t iterations) const {
  const int last = static_cast<int>(iterations) - 1;
  return position_ < 0 ? last : std::min(last, static_cast<int>(position_));
}

const Pose* SolverReplay::ShownEstimate(const std::vector<IterationReport>& iterations,
                                        const Pose* solution) const {
  const int shown = Shown(iterations.size());
  return shown >= 0 ? &iterations[shown].cam_from_lidar : solution;
}

SolverReplay::Request SolverReplay::Buttons(size_t iterations, bool solver_running) {
  Request request;
  const bool solved = iterations > 0;
  ImGui::BeginDisabled(solver_running);
  if (ImGui::Button("Run (F5)")) {
    request.run = true;
    position_ = -1;
    playing_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Step")) {
    if (!solved) {
      request.run = true;
      position_ = 0;
    } else {
      position_ = position_ < 0 ? 0 : position_ + 1;
      if (position_ >= static_cast<double>(iterations) - 1) position_ = -1;
    }
    playing_ = false;
  }
  ImGui::SameLine();
  if (ImGui::Button("Replay") && solved) {
    position_ = 0;
    playing_ = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("Reset")) {
    request.reset = true;
    position_ = -1;
  }
  ImGui::EndDisabled();
  return request;
}

void SolverReplay::CostPlot(const std::vector<IterationReport>& iterations, ImVec2 size) const {
  std::vector<float> log_cost;
  for (const IterationReport& it : iterations)
    log_cost.push_back(static_cast<float>(std::log10(std::max(it.cost, 1e-30))));
  const int shown = Shown(iterations.size());
  char overlay[96];
  std::snprintf(overlay, sizeof(overlay), "log10 cost; iteration %d of %zu: %.4e", shown,
                log_cost.size() - 1, iterations[shown].cost);
  ImGui::PlotLines("##cost", log_cost.data(), static_cast<int>(log_cost.size()), 0, overlay,
                   FLT_MAX, FLT_MAX, size);
  // Where the weights changed the cost jumps with them: an orange mark says so, so that a solve
  // that converged never looks like one that diverged.
  const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
  const ImVec2 pad = ImGui::GetStyle().FramePadding;
  const float inner = hi.x - lo.x - 2 * pad.x;
  bool any = false;
  for (size_t i = 1; i < iterations.size(); ++i) {
    if (!iterations[i].reweighted) continue;
    any = true;
    const float x = lo.x + pad.x + inner * static_cast<float>(i) / (iterations.size() - 1);
    ImGui::GetWindowDrawList()->AddLine(ImVec2(x, lo.y + pad.y), ImVec2(x, hi.y - pad.y),
                                        IM_COL32(255, 150, 40, 220), 2.0f);
  }
  if (any) {
    ImGui::GetWindowDrawList()->AddText(ImVec2(lo.x + pad.x, hi.y - pad.y - ImGui::GetFontSize()),
                                        IM_COL32(255, 150, 40, 255), "| re-weighted");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "orange marks: the weights changed there (outliers gated or variance factors "
          "re-estimated).\nThe cost jumps with the weights; the solve did not diverge.");
  }
}

}  // namespace calibench::ui
