#include "ui/widgets/pair_review.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

namespace calibench::ui {
namespace {

constexpr int kKeyF5 = 294;  // GLFW_KEY_F5

bool NamedKeyPressed(ImGuiKey key) { return KeyPressed(ImGui::GetKeyIndex(key)); }

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

}  // namespace

void PairProgress(const char* verb, int done, int total) {
  if (done >= total) return;
  char label[64];
  std::snprintf(label, sizeof(label), "%s %d / %d pairs", verb, done, total);
  ImGui::ProgressBar(static_cast<float>(done) / std::max(1, total), {-1, 0}, label);
}

std::optional<PairStatus> ReviewButtons(bool has_selection, const char* hint) {
  std::optional<PairStatus> clicked;
  ImGui::BeginDisabled(!has_selection);
  if (ImGui::Button("Accept (A)")) clicked = PairStatus::kAccepted;
  ImGui::SameLine();
  if (ImGui::Button("Reject (R)")) clicked = PairStatus::kRejected;
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("%s", hint);
  return clicked;
}

bool BeginPairsTable(std::initializer_list<PairColumn> columns) {
  if (!ImGui::BeginTable(
          "pairs", static_cast<int>(columns.size()),
          ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_BordersInnerV,
          ImVec2(0, ImGui::GetContentRegionAvail().y)))
    return false;
  ImGui::TableSetupScrollFreeze(0, 1);
  for (const PairColumn& column : columns)
    if (column.width > 0)
      ImGui::TableSetupColumn(column.name, ImGuiTableColumnFlags_WidthFixed, column.width);
    else
      ImGui::TableSetupColumn(column.name, ImGuiTableColumnFlags_WidthStretch);
  ImGui::TableHeadersRow();
  return true;
}

bool PairSelectable(int index, const std::string& id, bool selected, float row_height) {
  ImGui::PushID(index);
  // The selected row stands out more than the one under the mouse (ImGui's default is the
  // reverse: hovering looked like selecting).
  const ImVec4 accent = ImGui::GetStyleColorVec4(ImGuiCol_Header);
  ImGui::PushStyleColor(ImGuiCol_Header, ImVec4(accent.x, accent.y, accent.z, 0.75f));
  ImGui::PushStyleColor(ImGuiCol_HeaderHovered, ImVec4(accent.x, accent.y, accent.z, 0.25f));
  ImGui::PushStyleColor(ImGuiCol_HeaderActive, ImVec4(accent.x, accent.y, accent.z, 0.9f));
  const bool clicked =
      ImGui::Selectable(id.c_str(), selected,
                        ImGuiSelectableFlags_SpanAllColumns | ImGuiSelectableFlags_AllowItemOverlap,
                        ImVec2(0, row_height));
  ImGui::PopStyleColor(3);
  ImGui::PopID();
  return clicked;
}

void PairStatusText(PairStatus status, const std::string& text) {
  ImGui::TextColored(StatusColor(status), "%s", text.c_str());
}

bool KeyPressed(int key) { return key >= 0 && ImGui::IsKeyPressed(key, false); }

ReviewKeys ReadReviewKeys() {
  const bool ctrl = ImGui::GetIO().KeyCtrl;
  ReviewKeys keys;
  keys.accept = !ctrl && KeyPressed('A');
  keys.reject = !ctrl && KeyPressed('R');
  keys.next = NamedKeyPressed(ImGuiKey_DownArrow) || NamedKeyPressed(ImGuiKey_RightArrow);
  keys.previous = NamedKeyPressed(ImGuiKey_UpArrow) || NamedKeyPressed(ImGuiKey_LeftArrow);
  keys.run = NamedKeyPressed(ImGuiKey_Enter) || KeyPressed(kKeyF5);
  return keys;
}

}  // namespace calibench::ui
