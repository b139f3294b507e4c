#include "ui/widgets/error_popup.h"

#include <imgui.h>

namespace calibench::ui {

void ErrorPopup(const char* title, const std::string& message, bool* show, const char* hint) {
  if (*show) {
    ImGui::OpenPopup(title);
    *show = false;
  }
  if (!ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  ImGui::PushTextWrapPos(640);
  ImGui::TextColored({1.0f, 0.45f, 0.4f, 1}, "%s", message.c_str());
  if (hint) ImGui::TextDisabled("%s", hint);
  ImGui::PopTextWrapPos();
  if (ImGui::Button("OK")) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

}  // namespace calibench::ui
