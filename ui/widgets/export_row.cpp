#include "ui/widgets/export_row.h"

#include <imgui.h>

#include <cstdio>

#include "ui/widgets/path_field.h"

namespace calibench::ui {
namespace {

std::string Label(const std::optional<ExportFormat>& format) {
  return format ? ExportFormatName(*format) : "calibench result";
}

// A frame name in a short text field.
void FrameName(const char* id, std::string* name) {
  char text[128];
  std::snprintf(text, sizeof(text), "%s", name->c_str());
  ImGui::SetNextItemWidth(90);
  if (ImGui::InputText(id, text, sizeof(text))) *name = text;
}

}  // namespace

bool ExportRow(ExportChoice* choice) {
  ImGui::SetNextItemWidth(150);
  if (ImGui::BeginCombo("##export_format", Label(choice->format).c_str())) {
    if (ImGui::Selectable("calibench result", !choice->format)) {
      choice->format.reset();
      choice->path = "result.json";
    }
    for (const ExportFormat format : AllExportFormats())
      if (ImGui::Selectable(ExportFormatName(format).c_str(), choice->format == format)) {
        choice->format = format;
        choice->path = DefaultExportFileName(format);
      }
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "URDF joint, ROS 1 / ROS 2 static transform, OpenCV YAML, Autoware, "
        "Kalibr, 4x4 text; or Calibench's own result");
  if (choice->format) {
    ImGui::SameLine();
    FrameName("lidar##export", &choice->frames.lidar);  // the parent
    ImGui::SameLine();
    FrameName("camera##export", &choice->frames.camera);
    ImGui::SameLine();
    bool link = choice->frames.camera_frame == CameraFrame::kLink;
    if (ImGui::Checkbox("link frame", &link))
      choice->frames.camera_frame = link ? CameraFrame::kLink : CameraFrame::kOptical;
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "off: the camera's optical frame (z forward, x right, y down)\n"
          "on: its REP 103 link frame (x forward, y left, z up)");
  }
  ImGui::SameLine();
  return PathField("##export", &choice->path, "Export");
}

}  // namespace calibench::ui
