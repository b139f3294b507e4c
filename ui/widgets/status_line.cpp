#include "ui/widgets/status_line.h"

#include <imgui.h>

#include <algorithm>
#include <string>

namespace calibench::ui {

void StatusLine(const Rect& r, bool busy, bool is_error, const std::string& message,
                const std::string& right_text) {
  ImGui::SetNextWindowPos({r.x, r.y});
  ImGui::SetNextWindowSize({r.w, r.h});
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus);
  if (busy) {
    ImGui::TextColored({0.95f, 0.8f, 0.3f, 1}, "working");
    ImGui::SameLine();
  }
  // A message longer than the room left of the right-hand text is cut with "..." and shown whole
  // in a tooltip, rather than running under that text.
  const float right_x = std::max(ImGui::GetCursorPosX() + 120, r.w - 420);
  const float room = right_x - 20 - ImGui::GetCursorPosX();
  std::string shown = message;
  const bool cut = ImGui::CalcTextSize(message.c_str()).x > room;
  if (cut) {
    size_t fits = 0, too_long = message.size();
    while (fits + 1 < too_long) {  // the longest prefix that fits with the ellipsis
      const size_t middle = (fits + too_long) / 2;
      const std::string candidate = message.substr(0, middle) + "...";
      (ImGui::CalcTextSize(candidate.c_str()).x <= room ? fits : too_long) = middle;
    }
    shown = message.substr(0, fits) + "...";
  }
  if (is_error)
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", shown.c_str());
  else
    ImGui::TextUnformatted(shown.c_str());
  if (cut && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", message.c_str());
  ImGui::SameLine(right_x);
  ImGui::TextDisabled("%s", right_text.c_str());
  ImGui::End();
}

}  // namespace calibench::ui
