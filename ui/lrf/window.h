// The LRF workbench as a user runs it: a File menu over the workbench (Open LRF dataset, Export
// result, Quit), Ctrl+O, and a manifest dropped onto the window opens there. A manifest that does
// not open leaves the open one as it was and says why in a popup (and in the status line).
#pragma once

#include <string>

#include "ui/lrf/controller.h"
#include "ui/widgets/window_loop.h"

namespace calibench::ui {

// Runs the window until the user closes it; `controller` holds what is open and opens what the
// user chooses. The last failure to open is in *error (empty if none) when error is not null.
WindowRun RunLrfWindow(const WindowOptions& window, LrfController& controller,
                       std::string* error = nullptr);

}  // namespace calibench::ui
