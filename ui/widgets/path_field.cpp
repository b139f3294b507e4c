#include "ui/widgets/path_field.h"

#include <imgui.h>

#include <cstdio>

namespace calibench::ui {

bool PathField(const char* id, std::string* path, const char* button) {
  char text[512];
  std::snprintf(text, sizeof(text), "%s", path->c_str());
  ImGui::SetNextItemWidth(220);
  if (ImGui::InputText(id, text, sizeof(text))) *path = text;
  ImGui::SameLine();
  return ImGui::Button(button);
}

}  // namespace calibench::ui
