// The window's camera switch on a rig: another camera of it opens in a controller of its own.
#include "ui/lidar_camera/window_shell.h"

namespace calibench::ui {

void WindowShell::SelectCamera(const std::string& camera) {
  const Snapshot s = controller_->GetSnapshot();
  if (!s.rig || s.rig->cameras[s.rig->active].name == camera) return;
  try {
    auto opened = NewController();
    // While the rig solves, its cameras' solves are not all there: the new controller solves.
    if (!s.rig->solving) opened->CarryRig(*s.rig);
    opened->OpenDataset(s.rig->path, {}, ExistingSession::kResume, camera);
    const std::string pair = s.selected >= 0 ? s.pairs[s.selected].id : "";
    const auto pairs = opened->GetSnapshot().pairs;
    for (size_t i = 0; i < pairs.size(); ++i)
      if (pairs[i].id == pair) opened->Apply(SelectPair{static_cast<int>(i)});
    Replace(std::move(opened));
  } catch (const IoError& e) {
    error_ = e.what();
    show_error_ = true;
  }
}

}  // namespace calibench::ui
