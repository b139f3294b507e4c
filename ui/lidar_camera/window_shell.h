// The workbench window as a user runs it: a File menu over the workbench (Open dataset or
// folder, Open recording, Recent, Export, Quit), drag and drop of a dataset, folder, session or
// recording onto the window, and recordings imported on a thread behind a progress bar. Owns the
// controller of what is open and replaces it (with the workbench's GL resources) when the user
// opens something else; a failure to open shows in a popup and leaves the open work alone.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/board/board.h"
#include "core/capture/bag_import.h"
#include "ui/lidar_camera/controller.h"
#include "ui/state/recent_files.h"
#include "ui/widgets/file_browser.h"
#include "ui/widgets/report_runner.h"
#include "ui/widgets/window_loop.h"

namespace calibench::ui {

class Workbench;
struct ImportJob;  // a recording importing on its thread (window_shell.cpp)

struct ShellOptions {
  PipelineOptions pipeline;
  // The board seen in imported recordings; nullopt = the target.json beside the recording, else
  // the preset that fits its images.
  std::optional<BoardSpec> board;
  BagImportOptions import;
  std::filesystem::path recent_file = DefaultRecentFilesPath();
  bool auto_solve = true;  // every controller solves by itself (Controller::SetAutoSolve)
};

// What a path is to the workbench.
enum class OpenKind { kDataset, kSession, kRecording };
// By content: a recording (LooksLikeBag), a session file, else a dataset (manifest or folder).
OpenKind KindOfPath(const std::filesystem::path& path);

class WindowShell {
 public:
  explicit WindowShell(ShellOptions options);
  ~WindowShell();
  WindowShell(const WindowShell&) = delete;
  WindowShell& operator=(const WindowShell&) = delete;

  // What the window opens with; the command line's errors are thrown (IoError) before a window
  // exists. A recording starts importing and opens when done.
  void OpenDataset(const std::filesystem::path& dataset, ExistingSession existing,
                   const std::string& camera = "");
  void OpenSession(const std::filesystem::path& session);
  void ImportRecording(const std::filesystem::path& recording);
  // What the File menu, Recent and a drop do: any kind of path; failures go to the popup.
  void OpenFromUser(const std::filesystem::path& path);
  // Another camera of the open rig (the workbench's camera selector and strip): a controller on
  // that camera's session (resumed) replaces this one, the rig's other solves carried over and
  // the same capture selected; failures go to the popup.
  void SelectCamera(const std::string& camera);
  // Follows a capture folder or a recording being written (Controller::WatchFolder /
  // WatchRecording; File → Watch a capture…).
  void Watch(const std::filesystem::path& source);

  // Runs the window until the user closes it.
  WindowRun Run(const WindowOptions& options);

  // The controller of what is open (an empty one before anything is).
  Controller& controller() { return *controller_; }
  // The last failure shown in the popup (empty when none); the last import's summary.
  const std::string& error() const { return error_; }
  const std::optional<BagImportSummary>& last_import() const { return last_import_; }
  // Waits for a running import and opens its dataset (tests without a window).
  void FinishImport();

 private:
  bool Frame(Window& window, int width, int height, double seconds);
  float MenuBar();  // returns its height
  void FileMenu();
  void BoardMenu();  // the board of recordings opened from the menu
  void ExportMenu();
  void ReportMenuItem();  // File → Report…: `calibench report` on the saved session
  void Popups();
  // Opens what a finished import wrote; true while an import runs.
  bool PollImport();
  // Replaces the controller with one that opened `path`; the old one stays on failure.
  void Replace(std::unique_ptr<Controller> opened);
  std::unique_ptr<Controller> NewController() const;  // with the options' pipeline, auto-solve
  void Remember(const std::filesystem::path& session);

  ShellOptions options_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<Workbench> workbench_;  // made in the window's first frame (GL resources)
  RecentFiles recent_;
  FileBrowser browser_;
  std::unique_ptr<ImportJob> import_;
  ReportRunner report_;
  // The board presets (assets/targets), read when the menu first opens, not every frame.
  std::vector<std::pair<std::string, BoardSpec>> presets_;
  std::optional<BagImportSummary> last_import_;
  std::optional<std::filesystem::path> pending_open_;   // chosen during a frame, opened at the next
  std::optional<std::filesystem::path> pending_watch_;  // the same, to be watched
  std::optional<std::string> pending_camera_;           // the same, a rig camera to switch to
  std::uint64_t drawn_generation_ = 0;  // the controller's state the last frame showed
  bool choosing_watch_ = false;         // the browser is open for File → Watch folder…
  std::string error_;
  bool show_error_ = false;
  bool show_import_summary_ = false;
  bool quit_ = false;
};

}  // namespace calibench::ui
