#include "ui/widgets/layer_toggles.h"

#include <imgui.h>

namespace calibench::ui {

bool LayerToggles(gfx::SceneLayers* layers) {
  if (ImGui::SmallButton("layers")) ImGui::OpenPopup("##scene_layers");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("show or hide what the 3D view draws");
  bool changed = false;
  if (ImGui::BeginPopup("##scene_layers")) {
    for (const gfx::SceneLayers::Layer& layer : layers->layers()) {
      bool visible = layer.visible;
      if (ImGui::Checkbox(layer.name.c_str(), &visible)) {
        layers->SetVisible(layer.name, visible);
        changed = true;
      }
    }
    ImGui::EndPopup();
  }
  return changed;
}

}  // namespace calibench::ui
