#include "ui/widgets/status_line.h"

#include <imgui.h>

#include <algorithm>

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
  if (is_error)
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", message.c_str());
  else
    ImGui::TextUnformatted(message.c_str());
  ImGui::SameLine(std::max(ImGui::GetCursorPosX() + 20, r.w - 420));
  ImGui::TextDisabled("%s", right_text.c_str());
  ImGui::End();
}

}  // namespace calibench::ui
