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
}

}  // namespace calibench::ui
