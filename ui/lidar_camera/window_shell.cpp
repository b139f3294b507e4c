#include "ui/lidar_camera/window_shell.h"

#include <imgui.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/capture/recording_watch.h"
#include "core/io/dataset.h"
#include "core/recording/bag.h"
#include "core/results/export.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/error_popup.h"
#include "ui/widgets/report_runner.h"

namespace calibench::ui {

namespace fs = std::filesystem;

// A recording importing on its own thread; the window shows its progress and opens the dataset
// when it is done.
struct ImportJob {
  fs::path recording;
  std::thread thread;
  std::mutex mutex;  // guards the fields below
  std::string phase = "opening";
  double fraction = 0.0;
  std::optional<BagImportSummary> summary;
  std::string error;
  std::atomic<bool> done{false};

  ~ImportJob() {
    if (thread.joinable()) thread.join();
  }
};

OpenKind KindOfPath(const fs::path& path) {
  if (LooksLikeBag(path)) return OpenKind::kRecording;
  std::error_code error;
  if (fs::is_regular_file(path, error) && path.extension() == ".json" && IsSessionFile(path))
    return OpenKind::kSession;
  return OpenKind::kDataset;
}

WindowShell::WindowShell(ShellOptions options)
    : options_(std::move(options)), controller_(NewController()), recent_(options_.recent_file) {
  if (!recent_.load_error().empty()) {
    error_ = "the list of recent sessions was not read: " + recent_.load_error();
    show_error_ = true;
  }
}

WindowShell::~WindowShell() = default;

void WindowShell::Replace(std::unique_ptr<Controller> opened) {
  controller_ = std::move(opened);  // the old controller stops its worker and releases its lock
  workbench_.reset();               // its textures show the old dataset
  const fs::path session = controller_->GetSnapshot().session_path;
  if (!session.empty()) Remember(session);
}

void WindowShell::Remember(const fs::path& session) {
  const std::string why = recent_.Add(session);
  if (!why.empty()) {
    error_ = "the list of recent sessions was not saved: " + why;
    show_error_ = true;
  }
}

std::unique_ptr<Controller> WindowShell::NewController() const {
  auto controller = std::make_unique<Controller>(options_.pipeline);
  controller->SetAutoSolve(options_.auto_solve);
  return controller;
}

void WindowShell::OpenDataset(const fs::path& dataset, ExistingSession existing,
                              const std::string& camera) {
  auto opened = NewController();
  opened->OpenDataset(dataset, {}, existing, camera);
  Replace(std::move(opened));
}

void WindowShell::OpenSession(const fs::path& session) {
  auto opened = NewController();
  opened->OpenSession(session);
  Replace(std::move(opened));
}

void WindowShell::Watch(const fs::path& source) {
  auto watching = NewController();
  // Each opens its dataset folder once the camera and the target are known.
  if (IsRecordingSource(source))
    watching->WatchRecording(source, DefaultImportFolder(source), options_.board, options_.import);
  else
    watching->WatchFolder(source);
  Replace(std::move(watching));
}

void WindowShell::ImportRecording(const fs::path& recording) {
  if (import_) {
    error_ = "an import is running; wait for it to finish";
    show_error_ = true;
    return;
  }
  import_ = std::make_unique<ImportJob>();
  ImportJob* job = import_.get();
  job->recording = recording;
  const fs::path out = DefaultImportFolder(recording);
  job->thread = std::thread([job, out, board = options_.board, options = options_.import] {
    try {
      BagImportSummary summary =
          ImportBag(job->recording, out, board, options,
                    [job](const std::string& phase, std::int64_t done, std::int64_t total) {
                      std::lock_guard<std::mutex> lock(job->mutex);
                      job->phase = phase;
                      job->fraction = total > 0 ? static_cast<double>(done) / total : 0.0;
                    });
      std::lock_guard<std::mutex> lock(job->mutex);
      job->summary = std::move(summary);
    } catch (const std::exception& e) {  // IoError, or a filesystem error writing the folder
      std::lock_guard<std::mutex> lock(job->mutex);
      job->error = e.what();
    }
    job->done = true;
  });
}

namespace {

// The session file opening `path` would edit (the controller's rule: beside the dataset).
fs::path SessionOpenedBy(const fs::path& path, OpenKind kind) {
  return kind == OpenKind::kSession ? path : DefaultSessionPath(path);
}

bool SameFile(const fs::path& a, const fs::path& b) {
  std::error_code error;
  return !a.empty() && !b.empty() &&
         fs::weakly_canonical(a, error) == fs::weakly_canonical(b, error);
}

}  // namespace

void WindowShell::OpenFromUser(const fs::path& path) {
  const OpenKind kind = KindOfPath(path);
  if (kind != OpenKind::kRecording &&
      SameFile(SessionOpenedBy(path, kind), controller_->GetSnapshot().session_path)) {
    error_ = path.string() + " is open in this window already";
    show_error_ = true;
    return;
  }
  try {
    switch (kind) {
      case OpenKind::kRecording:
        ImportRecording(path);
        break;
      case OpenKind::kSession:
        OpenSession(path);
        break;
      case OpenKind::kDataset:
        // Opening a dataset again resumes its session: an hour of edits is never overwritten.
        OpenDataset(path, ExistingSession::kResume);
        break;
    }
  } catch (const IoError& e) {
    error_ = e.what();
    show_error_ = true;
  }
}

bool WindowShell::PollImport() {
  if (!import_) return false;
  if (!import_->done) return true;
  std::unique_ptr<ImportJob> job = std::move(import_);
  job->thread.join();
  if (!job->error.empty()) {
    error_ = job->error;
    show_error_ = true;
    return false;
  }
  last_import_ = job->summary;
  show_import_summary_ = true;
  OpenFromUser(job->summary->manifest);
  return false;
}

void WindowShell::FinishImport() {
  if (import_ && import_->thread.joinable()) {
    while (!import_->done) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  PollImport();
}

WindowRun WindowShell::Run(const WindowOptions& options) {
  WindowRun run;
  const auto window = Window::Open(options, &run.why);
  if (!window) return run;
  run.opened = true;
  run.last_frame = window->Run(
      [&](int width, int height, double seconds) { return Frame(*window, width, height, seconds); },
      [&] { return controller_->Generation() != drawn_generation_; });
  run.stats = window->stats();
  if (import_) FinishImport();  // a closed window does not abandon an import half-written
  return run;
}

bool WindowShell::Frame(Window& window, int width, int height, double seconds) {
  if (pending_open_) OpenFromUser(*std::exchange(pending_open_, std::nullopt));
  if (pending_watch_) Watch(*std::exchange(pending_watch_, std::nullopt));
  if (pending_camera_) SelectCamera(*std::exchange(pending_camera_, std::nullopt));
  for (const std::string& dropped : window.TakeDroppedPaths()) pending_open_ = dropped;
  const bool importing = PollImport();  // may open a dataset, replacing the workbench
  if (!workbench_) workbench_ = std::make_unique<Workbench>();
  const float top = MenuBar();
  const Snapshot snapshot = controller_->GetSnapshot();
  drawn_generation_ = snapshot.generation;
  const auto intents = workbench_->Frame(snapshot, width, height, Layout::kWorkbench, seconds, top);
  for (const Intent& intent : intents) {
    // A camera of the rig is another controller's (its own session): the next frame opens it.
    if (const auto* camera = std::get_if<ui::SelectCamera>(&intent))
      pending_camera_ = camera->camera;
    else
      controller_->Apply(intent);
  }
  if (const auto chosen = browser_.Draw())
    (std::exchange(choosing_watch_, false) ? pending_watch_ : pending_open_) = *chosen;
  if (!browser_.IsOpen()) choosing_watch_ = false;
  Popups();
  if (quit_) window.RequestClose();
  return importing || report_.Running() || !intents.empty() || workbench_->Animating(snapshot) ||
         workbench_->NeedsAnotherFrame() || pending_open_.has_value() ||
         pending_camera_.has_value();
}

float WindowShell::MenuBar() {
  if (ImGui::GetIO().KeyCtrl && ImGui::IsKeyPressed('O', false))
    browser_.Open(controller_->GetSnapshot().dataset_path, "Open dataset, session or recording");
  if (!ImGui::BeginMainMenuBar()) return 0.0f;
  FileMenu();
  const float height = ImGui::GetWindowSize().y;
  ImGui::EndMainMenuBar();
  return height;
}

void WindowShell::FileMenu() {
  if (!ImGui::BeginMenu("File")) return;
  const fs::path here = controller_->GetSnapshot().dataset_path;
  if (ImGui::MenuItem("Open dataset or session...", "Ctrl+O"))
    browser_.Open(here, "Open dataset, session or recording");
  if (ImGui::MenuItem("Open recording (.bag .db3 .mcap)...", nullptr, false, !import_))
    browser_.Open(here, "Open a recording to import");
  if (ImGui::MenuItem("Watch a capture being written...")) {
    browser_.Open(here, "Watch a capture folder or a recording being written");
    choosing_watch_ = true;
  }
  if (ImGui::BeginMenu("Recent sessions")) {
    const auto recent = recent_.Paths();
    if (recent.empty()) ImGui::TextDisabled("none yet");
    for (const fs::path& path : recent)
      if (ImGui::MenuItem(path.string().c_str())) pending_open_ = path;
    ImGui::EndMenu();
  }
  BoardMenu();
  ImGui::Separator();
  ExportMenu();
  ReportMenuItem();
  ImGui::Separator();
  if (ImGui::MenuItem("Quit")) quit_ = true;
  ImGui::EndMenu();
}

void WindowShell::BoardMenu() {
  if (!ImGui::BeginMenu("Board in recordings")) return;
  if (ImGui::MenuItem("automatic", nullptr, !options_.board)) options_.board.reset();
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("the target.json beside the recording, else the preset that fits the images");
  // The presets Calibench ships (assets/targets/*.json; a board dropped there shows up too).
  if (presets_.empty()) presets_ = ShippedTargetPresets();
  for (const auto& [name, board] : presets_) {
    const bool chosen = options_.board && board.type == options_.board->type &&
                        board.cols == options_.board->cols && board.rows == options_.board->rows &&
                        board.square_size == options_.board->square_size;
    if (ImGui::MenuItem(name.c_str(), nullptr, chosen)) options_.board = board;
  }
  ImGui::TextDisabled("or --board FILE on the command line");
  ImGui::EndMenu();
}

void WindowShell::ExportMenu() {
  const Snapshot snapshot = controller_->GetSnapshot();
  drawn_generation_ = snapshot.generation;
  if (!ImGui::BeginMenu("Export", snapshot.solver.result.has_value())) return;
  ImGui::TextDisabled("next to the session; the solver panel names frames and files");
  if (ImGui::MenuItem("calibench result (result.json)"))
    controller_->Apply(ExportResult{"result.json", std::nullopt, {}});
  for (const ExportFormat format : AllExportFormats()) {
    const std::string label = ExportFormatName(format) + " (" + DefaultExportFileName(format) + ")";
    if (ImGui::MenuItem(label.c_str()))
      controller_->Apply(ExportResult{DefaultExportFileName(format), format, {}});
  }
  ImGui::EndMenu();
}

void WindowShell::ReportMenuItem() {
  const Snapshot snapshot = controller_->GetSnapshot();
  drawn_generation_ = snapshot.generation;
  report_.MenuItem(snapshot.session_path, snapshot.solver.result.has_value(),
                   "re-solving each pair left out, drawing the views");
}

void WindowShell::Popups() {
  if (std::string failure = report_.Draw(); !failure.empty())
    error_ = std::move(failure), show_error_ = true;
  if (import_ && !ImGui::IsPopupOpen("Importing")) ImGui::OpenPopup("Importing");
  if (ImGui::BeginPopupModal("Importing", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    if (!import_) {
      ImGui::CloseCurrentPopup();  // done: the dataset is open, or the error shows next
    } else {
      std::lock_guard<std::mutex> lock(import_->mutex);
      ImGui::Text("%s", import_->recording.filename().c_str());
      ImGui::ProgressBar(
          static_cast<float>(import_->fraction), {420, 0},
          (import_->phase + " " + std::to_string(static_cast<int>(import_->fraction * 100)) + "%")
              .c_str());
      ImGui::TextDisabled("clouds paired with images; still boards only; then the files");
    }
    ImGui::EndPopup();
  }
  ErrorPopup("Cannot open", error_, &show_error_);
  if (show_import_summary_ && !show_error_ && last_import_) {
    ImGui::OpenPopup("Imported");
    show_import_summary_ = false;
  }
  if (ImGui::BeginPopupModal("Imported", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    const BagImportSummary& s = *last_import_;
    ImGui::Text("%zu pairs from %lld clouds (%s) and %lld images (%s)", s.pair_ids.size(),
                static_cast<long long>(s.clouds), s.cloud_topic.c_str(),
                static_cast<long long>(s.images), s.image_topic.c_str());
    ImGui::Text("board: %s", s.board_source.c_str());
    ImGui::Text("searched %d images for the board (%d sweeps tried), found in %d",
                s.images_searched, s.tries, s.boards_seen);
    for (const auto& [reason, count] : s.dropped)
      ImGui::BulletText("dropped %d: %s", count, reason.c_str());
    ImGui::TextDisabled("%s", s.manifest.c_str());
    if (ImGui::Button("OK")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
}

}  // namespace calibench::ui
