// Toolbars that wrap: the next item goes on the same line when it fits in the view, else on a new
// one, so that narrow windows (1024 x 640 and below) cut nothing off.
#pragma once

#include <imgui.h>

namespace calibench::ui {

// The width an item will take: its frame (`frame_width`, 0 = a button for `label`) and its label.
inline float ToolbarItemWidth(const char* label, float frame_width = 0.0f) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float text = ImGui::CalcTextSize(label, nullptr, true).x;
  if (frame_width <= 0.0f) return text + 2 * style.FramePadding.x;
  return frame_width + (text > 0 ? style.ItemInnerSpacing.x + text : 0.0f);
}

// Call between items: SameLine() when an item `next_width` wide still fits after the last one.
inline void SameLineIfFits(float next_width) {
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  if (ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x + next_width <= right)
    ImGui::SameLine();
}

}  // namespace calibench::ui
