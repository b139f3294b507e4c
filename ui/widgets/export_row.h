// The workbench's Export: what to write (a calibench result, or a file a robot loads in one of
// the export formats), the frames' names and the camera frame for those, the file, the button.
#pragma once

#include <optional>
#include <string>

#include "core/results/export.h"

namespace calibench::ui {

struct ExportChoice {
  std::optional<ExportFormat> format;  // nullopt: a calibench.result.v1 JSON
  ExportFrames frames;
  std::string path = "result.json";  // relative: next to the session
};

// Draws the row; true when the user clicked Export. Choosing a format puts its usual file name
// in the path field.
bool ExportRow(ExportChoice* choice);

}  // namespace calibench::ui
