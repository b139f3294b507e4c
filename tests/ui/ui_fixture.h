// A small simulated dataset shared by the workbench tests (made once per test process).
#pragma once

#include <filesystem>

#include "ui/lidar_camera/controller.h"

namespace calibench::test {

// Four OS0-128 + pinhole pairs with an A3 checkerboard, seed 3: the goldens depend on it.
std::filesystem::path UiDataset();

}  // namespace calibench::test

namespace calibench::ui {

// The controller's state once its queued work is done.
inline Snapshot Loaded(Controller& controller) {
  controller.WaitIdle();
  return controller.GetSnapshot();
}

}  // namespace calibench::ui
