#include "ui/lrf/window.h"

#include <imgui.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <utility>

#include "core/io/dataset_source.h"
#include "core/session/lrf_calibration_job.h"
#include "ui/lrf/workbench.h"
#include "ui/widgets/error_popup.h"
#include "ui/widgets/file_browser.h"
#include "ui/widgets/report_runner.h"

namespace calibench::ui {
namespace {
namespace fs = std::filesystem;

// Where the File menu's export goes: beside the manifest, as the lidar-camera window's exports
// go beside the session.
constexpr const char* kMenuExportFile = "lrf_result.json";

// Whether `path` is a LiDAR-camera dataset (any manifest name, the folder form).
bool LooksLikeLidarCameraDataset(const fs::path& path) {
  std::string ignored;
  const auto source = RecogniseDataset(path, &ignored);
  return source && source->kind == DatasetKind::kLidarCamera;
}

class LrfWindowShell {
 public:
  explicit LrfWindowShell(LrfController& controller) : controller_(controller) {}

  // One frame; true while the next one would differ without input.
  bool Frame(Window& window, int width, int height, double seconds) {
    if (pending_open_) Open(*std::exchange(pending_open_, std::nullopt));
    for (const std::string& dropped : window.TakeDroppedPaths()) pending_open_ = dropped;
    if (!workbench_) workbench_ = std::make_unique<LrfWorkbench>();
    const float top = MenuBar();
    const LrfSnapshot snapshot = controller_.GetSnapshot();
    const auto intents =
        workbench_->Frame(snapshot, width, height, LrfLayout::kWorkbench, seconds, top);
    for (const LrfIntent& intent : intents) controller_.Apply(intent);
    if (const auto chosen = browser_.Draw()) pending_open_ = *chosen;
    if (std::string failure = report_.Draw(); !failure.empty())
      error_ = std::move(failure), show_error_ = true, lidar_camera_refused_ = false;
    ErrorPopup(
        "Cannot open", error_, &show_error_,
        lidar_camera_refused_
            ? "a LiDAR-camera dataset: it opens in its own window, calibench gui --dataset PATH"
            : nullptr);
    if (quit_) window.RequestClose();
    return !intents.empty() || workbench_->Animating(snapshot) || pending_open_.has_value() ||
           report_.Running();
  }

  const std::string& error() const { return error_; }

 private:
  void Open(const fs::path& manifest) {
    // An LRF session (a dropped calibench.lrf-session.json) opens with the manifest it names.
    if (IsLrfSession(manifest) ? controller_.OpenSession(manifest) : controller_.Open(manifest)) {
      workbench_.reset();  // its textures and view keys show the old dataset
      return;
    }
    error_ = controller_.GetSnapshot().status_line;
    show_error_ = true;
    lidar_camera_refused_ = LooksLikeLidarCameraDataset(manifest);
  }

  float MenuBar() {
    const fs::path here = controller_.GetSnapshot().manifest;
    if (ImGui::GetIO().KeyCtrl && ImGui::IsKeyPressed('O', false))
      browser_.Open(here,
                    "Open an LRF dataset (calibench.lrf-dataset.v1 manifest) or an LRF session");
    if (!ImGui::BeginMainMenuBar()) return 0.0f;
    if (ImGui::BeginMenu("File")) {
      if (ImGui::MenuItem("Open LRF dataset or session...", "Ctrl+O"))
        browser_.Open(here,
                      "Open an LRF dataset (calibench.lrf-dataset.v1 manifest) or an LRF session");
      ImGui::Separator();
      const bool solved = controller_.GetSnapshot().solver.solution.has_value();
      const std::string label = std::string("Export result (") + kMenuExportFile + ")";
      if (ImGui::MenuItem(label.c_str(), nullptr, false, solved))
        controller_.Apply(LrfExportResult{kMenuExportFile});  // relative: beside the manifest
      ImGui::TextDisabled("beside the manifest; the solver panel exports anywhere");
      const LrfSnapshot s = controller_.GetSnapshot();
      report_.MenuItem(s.session_path, s.solver.solution.has_value() && s.save_error.empty(),
                       "re-solving each observation left out");
      ImGui::Separator();
      if (ImGui::MenuItem("Quit")) quit_ = true;
      ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Edit")) {
      const LrfSnapshot s = controller_.GetSnapshot();
      if (ImGui::MenuItem("Undo", "Ctrl+Z", false, s.can_undo)) controller_.Apply(LrfUndo{});
      if (ImGui::MenuItem("Redo", "Ctrl+Y", false, s.can_redo)) controller_.Apply(LrfRedo{});
      ImGui::Separator();
      ImGui::TextDisabled("session (saved as you go): %s",
                          s.session_path.empty() ? "none" : s.session_path.c_str());
      if (!s.session_note.empty()) ImGui::TextDisabled("%s", s.session_note.c_str());
      ImGui::EndMenu();
    }
    const float height = ImGui::GetWindowSize().y;
    ImGui::EndMainMenuBar();
    return height;
  }

  LrfController& controller_;
  std::unique_ptr<LrfWorkbench> workbench_;
  FileBrowser browser_;
  ReportRunner report_;  // File → Report…
  std::optional<fs::path> pending_open_;
  std::string error_;
  bool show_error_ = false;
  bool lidar_camera_refused_ = false;  // the refused path is a LiDAR-camera dataset
  bool quit_ = false;
};

}  // namespace

WindowRun RunLrfWindow(const WindowOptions& window_options, LrfController& controller,
                       std::string* error) {
  WindowRun run;
  const auto window = Window::Open(window_options, &run.why);
  if (!window) return run;
  run.opened = true;
  LrfWindowShell shell(controller);
  run.last_frame = window->Run([&](int width, int height, double seconds) {
    return shell.Frame(*window, width, height, seconds);
  });
  run.stats = window->stats();
  if (error) *error = shell.error();
  return run;
}

}  // namespace calibench::ui
