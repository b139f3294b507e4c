#include "ui/widgets/solution_readouts.h"

#include <imgui.h>

namespace calibench::ui {

void PoseReadout(const char* name, const char* words, const Pose& pose) {
  ImGui::Text("%s", name);
  ImGui::SameLine();
  ImGui::TextDisabled("(%s)", words);
  for (int r = 0; r < 3; ++r)
    ImGui::Text("  % .5f % .5f % .5f | % .4f", pose.matrix()(r, 0), pose.matrix()(r, 1),
                pose.matrix()(r, 2), pose.matrix()(r, 3));
}

void StdReadout(const Vec3& translation_mm, const Vec3& rotation_deg) {
  ImGui::Text("std (camera x/y/z): %.1f %.1f %.1f mm, %.3f %.3f %.3f deg", translation_mm.x(),
              translation_mm.y(), translation_mm.z(), rotation_deg.x(), rotation_deg.y(),
              rotation_deg.z());
}

void ObservabilityReadout(const ObservabilityReport& report, const std::string& details,
                          const char* advice) {
  if (report.well_constrained) {
    ImGui::TextColored({0.45f, 0.85f, 0.45f, 1}, "well constrained (%s)", details.c_str());
    return;
  }
  ImGui::TextColored({1.0f, 0.45f, 0.3f, 1}, "%s", advice);
  for (const std::string& d : report.weak_directions)
    ImGui::TextColored({1.0f, 0.6f, 0.4f, 1}, "  weak: %s", d.c_str());
}

}  // namespace calibench::ui
