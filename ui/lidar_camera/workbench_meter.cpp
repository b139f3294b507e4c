// The meter in the solver panel: σ per camera axis as a bar against the user's goal (editable),
// the weakest direction in words, done when the stop rule says so, and σ over the solves.
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/target/board_choice.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/path_field.h"

namespace calibench::ui {
namespace {

const ImVec4 kUnder(0.45f, 0.85f, 0.45f, 1), kOver(1.0f, 0.55f, 0.35f, 1);

// One axis: its σ as a share of the goal (the bar full at twice the goal), green under it.
void SigmaBar(const char* axis, double sigma, double goal, const char* unit) {
  const double ratio = sigma / goal;
  char label[48];
  std::snprintf(label, sizeof(label), unit[0] == 'm' ? "%s %.2f %s" : "%s %.3f %s", axis, sigma,
                unit);
  ImGui::PushStyleColor(ImGuiCol_PlotHistogram, ratio <= 1.0 ? kUnder : kOver);
  ImGui::ProgressBar(static_cast<float>(std::min(1.0, 0.5 * ratio)), ImVec2(118, 0), label);
  ImGui::PopStyleColor();
}

}  // namespace

void Workbench::MeterRows(const Snapshot& s, std::vector<Intent>* intents) {
  CaptureGoal goal = s.goal;
  ImGui::TextUnformatted("goal (1 sigma per axis):");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70);
  ImGui::InputDouble("mm", &goal.translation_mm, 0, 0, "%.2f");
  const bool mm_done = ImGui::IsItemDeactivatedAfterEdit();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70);
  ImGui::InputDouble("deg", &goal.rotation_deg, 0, 0, "%.3f");
  bool edited = mm_done || ImGui::IsItemDeactivatedAfterEdit();
  // How precisely the board is held: the next pose is chosen so a hand's error keeps it usable.
  double hand_cm = 100 * s.hand_tolerance_m, hand_deg = s.hand_tolerance_deg;
  ImGui::SameLine();
  ImGui::TextUnformatted("  hand within +-");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(50);
  ImGui::InputDouble("cm##hand", &hand_cm, 0, 0, "%.0f");
  edited |= ImGui::IsItemDeactivatedAfterEdit();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(50);
  ImGui::InputDouble("deg##hand", &hand_deg, 0, 0, "%.0f");
  edited |= ImGui::IsItemDeactivatedAfterEdit();
  if (edited) intents->push_back(SetGoal{goal, hand_cm / 100, hand_deg});
  if (!s.meter) return GuideRows(s);
  const CaptureState& m = *s.meter;
  ImGui::SameLine();
  if (m.done)
    ImGui::TextColored(kUnder, "DONE: every sigma under the goal and trusted (%d pairs)",
                       m.pairs_used);
  else
    ImGui::TextColored(kOver, "not done (%d pairs)", m.pairs_used);
  static const char* const kAxes[] = {"t x", "t y", "t z", "r x", "r y", "r z"};
  for (int i = 0; i < 6; ++i) {
    if (i > 0) ImGui::SameLine();
    if (i < 3)
      SigmaBar(kAxes[i], m.sigma_t_mm[i], s.goal.translation_mm, "mm");
    else
      SigmaBar(kAxes[i], m.sigma_r_deg[i - 3], s.goal.rotation_deg, "deg");
  }
  ImGui::PushTextWrapPos(0);
  if (!m.goal_met) ImGui::TextColored(kOver, "weakest: %s", m.weakest.c_str());
  if (!m.trustworthy) ImGui::TextDisabled("sigma not final: %s", m.trust_note.c_str());
  ImGui::PopTextWrapPos();
  // The worst σ/goal over the six axes, solve by solve: the capture's progress.
  if (s.meter_history.size() >= 2) {
    std::vector<float> worst;
    for (const MeterPoint& p : s.meter_history)
      worst.push_back(static_cast<float>(std::max(p.sigma_t_mm.maxCoeff() / s.goal.translation_mm,
                                                  p.sigma_r_deg.maxCoeff() / s.goal.rotation_deg)));
    char overlay[64];
    std::snprintf(overlay, sizeof(overlay), "worst sigma / goal: %d to %d pairs",
                  s.meter_history.front().pairs, s.meter_history.back().pairs);
    ImGui::PlotLines("##meter_history", worst.data(), static_cast<int>(worst.size()), 0, overlay,
                     0.0f, std::max(2.0f, *std::max_element(worst.begin(), worst.end())),
                     ImVec2(360, 40));
  }
  GuideRows(s);
}

// Where to hold the board next (the ghost board in the camera and 3D views) in `advise`'s
// words, and whether the newest pair matched the ghost shown when it was taken.
void Workbench::GuideRows(const Snapshot& s) {
  ImGui::PushTextWrapPos(0);
  if (!s.watching.empty())
    ImGui::TextDisabled("watching %s: %d pairs so far", s.watching.string().c_str(),
                        static_cast<int>(s.pairs.size()));
  if (s.next_pose)
    ImGui::TextColored(ImVec4(0.47f, 1.0f, 0.55f, 1), "next pose (the green ghost board): %s",
                       s.next_pose->words.c_str());
  else if (!s.next_pose_failure.empty())
    ImGui::TextDisabled("next pose: %s", s.next_pose_failure.c_str());
  if (!s.ghost_match.empty())
    ImGui::TextColored(s.ghost_matched ? kUnder : kOver, "%s", s.ghost_match.c_str());
  ImGui::PopTextWrapPos();
}

void Workbench::BoardPicker(const Snapshot& s, std::vector<Intent>* intents) {
  ++picker_frames_;
  ImGui::SetNextWindowSize(ImVec2(560, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Which board?")) return ImGui::End();
  ImGui::PushTextWrapPos(0);
  ImGui::TextColored(kOver, "%s", s.board_problem.c_str());
  ImGui::TextDisabled("The capture goes on; its pairs are held until the board is known.");
  ImGui::PopTextWrapPos();
  const std::vector<std::string> presets = ChoosablePresets();
  std::vector<const char*> names;
  for (const std::string& name : presets) names.push_back(name.c_str());
  picked_preset_ = std::clamp(picked_preset_, 0, static_cast<int>(names.size()) - 1);
  ImGui::SetNextItemWidth(160);
  ImGui::Combo("##preset", &picked_preset_, names.data(), static_cast<int>(names.size()));
  ImGui::SameLine();
  if (ImGui::Button("Use this preset")) intents->push_back(PickBoard{presets[picked_preset_]});
  if (PathField("##target_file", &picked_target_file_, "Use this target file"))
    intents->push_back(PickBoard{picked_target_file_});
  ImGui::End();
}

}  // namespace calibench::ui
