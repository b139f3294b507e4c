// `calibench gui` (the workbench window) and `calibench render` (the same views, headless): flags
// in, calls to ui/widgets (window_loop.h, headless_render.h) out.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "core/base/image.h"
#include "core/io/image_io.h"
#include "core/lidar_camera/rig.h"
#include "core/recording/bag.h"
#include "core/session/job.h"
#include "core/session/lrf_calibration_job.h"
#include "ui/gfx/context.h"
#include "ui/lidar_camera/controller.h"
#include "ui/lidar_camera/window_shell.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lrf/controller.h"
#include "ui/lrf/window.h"
#include "ui/lrf/workbench.h"
#include "ui/widgets/headless_render.h"
#include "ui/widgets/imgui_host.h"
#include "ui/widgets/window_loop.h"

namespace calibench::app {
namespace {

bool ParseSize(const std::string& text, int* width, int* height) {
  return std::sscanf(text.c_str(), "%dx%d", width, height) == 2 && *width >= 64 && *height >= 64 &&
         *width <= 8192 && *height <= 8192;
}

// Parses the command line, then `size` (bound to --size) into *width x *height: nullopt to go
// on, else the exit code (kOk after --help).
std::optional<int> ParseFlags(CLI::App& app, int argc, char** argv, const std::string& size,
                              const char* command, int* width, int* height) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  if (!ParseSize(size, width, height)) {
    std::fprintf(stderr, "calibench %s: --size must be WxH, e.g. 1600x900\n", command);
    return kUsage;
  }
  return std::nullopt;
}

// Opens the dataset or session the flags name; false (message printed) when neither is given.
bool OpenInput(ui::Controller& controller, const std::string& dataset, const std::string& session,
               const char* command, ui::ExistingSession existing = ui::ExistingSession::kReplace,
               const std::string& camera = "") {
  if (!session.empty()) {
    controller.OpenSession(session, existing != ui::ExistingSession::kInMemory);
  } else if (!dataset.empty()) {
    controller.OpenDataset(dataset, {}, existing, camera);
  } else {
    std::fprintf(stderr, "calibench %s: give --dataset or --session\n", command);
    return false;
  }
  return true;
}

// The window the gui flags ask for; with --screenshot its last frame is kept.
ui::WindowOptions WindowOptionsOf(int width, int height, const char* title,
                                  const std::string& screenshot, const GuiWindowFlags& quit) {
  ui::WindowOptions options;
  options.width = width;
  options.height = height;
  options.title = title;
  options.quit_after_frames = quit.after_frames;
  options.capture_last_frame = !screenshot.empty();
  options.quit_after_seconds = quit.after_seconds;
  options.test_drops = quit.test_drops;
  options.frame_log = quit.frame_log;
  if (!screenshot.empty()) {
    options.screenshot_every_s = quit.screenshot_every_s;
    const std::filesystem::path shot(screenshot);
    options.screenshots_prefix = (shot.parent_path() / shot.stem()).string();
  }
  return options;
}

// The last save failed (the window showed it on its status line): say so on stderr too, with
// an exit code, so that a script or a terminal user does not take the session for saved.
template <typename AnyController>
int ReportSaveFailure(AnyController& controller, const char* command) {
  controller.WaitIdle();
  const auto snapshot = controller.GetSnapshot();
  if (snapshot.save_error.empty()) return kOk;
  std::fprintf(stderr, "calibench %s: the session was not saved: %s\n", command,
               snapshot.save_error.c_str());
  return kInputError;
}

// The exit code of a window run; writes the screenshot it captured.
int FinishWindow(const ui::WindowRun& run, const std::string& screenshot) {
  if (!run.opened) {
    std::fprintf(stderr,
                 "calibench gui: cannot open a window: %s\n"
                 "(no display? `calibench render` draws the same views to PNG)\n",
                 run.why.c_str());
    return kInputError;
  }
  if (run.last_frame) {
    SaveImage(screenshot, *run.last_frame);
    std::printf("wrote %s\n", screenshot.c_str());
  }
  std::printf(
      "frames drawn: %d (%d with nothing moving for a second); longest %.1f ms, %d over 50 ms\n",
      run.stats.frames, run.stats.quiet_frames, run.stats.max_frame_ms, run.stats.slow_frames);
  return kOk;
}

// The LRF workbench in a window (a calibench.lrf-dataset.v1 manifest, or an LRF session), with
// its File and Edit menus; it resumes the session beside the manifest unless `fresh`.
int RunLrfGuiWindow(const std::string& dataset, const std::string& session,
                    const ui::WindowOptions& window, const std::string& screenshot, bool fresh) {
  ui::LrfController controller;
  // A bad manifest or session shows its error in the window's status line.
  if (!session.empty())
    controller.OpenSession(session);
  else
    controller.Open(dataset,
                    fresh ? ui::ExistingSession::kStartFresh : ui::ExistingSession::kResume);
  std::string error;
  int code = FinishWindow(ui::RunLrfWindow(window, controller, &error), screenshot);
  if (!error.empty()) std::fprintf(stderr, "calibench gui: %s\n", error.c_str());
  const ui::LrfSnapshot last = controller.GetSnapshot();
  if (!last.manifest.empty()) std::printf("open at the end: %s\n", last.manifest.c_str());
  if (!last.session_path.empty()) std::printf("session: %s\n", last.session_path.c_str());
  if (code == kOk) code = ReportSaveFailure(controller, "gui");
  return code;
}

// The headless GL context of a render, or nullptr after printing `failure`: why.
std::unique_ptr<gfx::GlContext> OpenHeadless(gfx::HeadlessBackend backend, const char* failure) {
  std::string why;
  auto context = gfx::CreateHeadlessContext(backend, &why);
  if (!context) std::fprintf(stderr, "%s: %s\n", failure, why.c_str());
  return context;
}

// Writes a render of `view` (nullopt: the pair was not found in `where`).
int SaveShot(const std::optional<ImageU8>& picture, const ui::HeadlessShot& shot,
             const std::string& view, const std::string& out, const std::string& where,
             const gfx::GlContext& context) {
  if (!picture) {
    std::fprintf(stderr, "calibench render: no pair '%s' in %s\n", shot.pair_id.c_str(),
                 where.c_str());
    return kInputError;
  }
  SaveImage(out, *picture);
  std::printf("wrote %s (%dx%d, %s, %s)\n", out.c_str(), shot.width, shot.height, view.c_str(),
              context.Description().c_str());
  return kOk;
}

int RenderLrfHeadless(const std::string& dataset, const ui::HeadlessShot& shot,
                      const std::string& view, const std::string& out,
                      gfx::HeadlessBackend backend) {
  ui::LrfLayout layout;
  if (!ui::ParseLrfLayout(view, &layout)) {
    std::fprintf(stderr,
                 "calibench render: for an LRF dataset --view must be scan, depth, 3d or "
                 "workbench\n");
    return kUsage;
  }
  const auto context = OpenHeadless(backend, "calibench render: no headless OpenGL");
  if (!context) return kInputError;
  ui::LrfController controller;
  // In memory: render leaves the session beside the manifest alone.
  if (!controller.Open(dataset, ui::ExistingSession::kInMemory)) {
    std::fprintf(stderr, "calibench render: %s\n", controller.GetSnapshot().status_line.c_str());
    return kInputError;
  }
  const auto picture = ui::RenderShot<ui::LrfWorkbench, ui::LrfSelectPair, ui::LrfRunSolver>(
      controller, layout, shot);
  return SaveShot(picture, shot, view, out, dataset, *context);
}

}  // namespace

int RunGuiWindow(const std::string& dataset, const std::string& session, int width, int height,
                 const std::string& screenshot, const GuiWindowFlags& quit) {
  ui::ShellOptions options;
  try {
    options.board = BoardFromFlag(quit.board);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "calibench gui: --board: %s\n", e.what());
    return kUsage;
  }
  options.auto_solve = !quit.no_auto_solve;
  ui::WindowShell shell(options);
  // The window resumes the session beside the dataset (or, with --fresh, backs it up first).
  if (!quit.watch.empty()) {
    shell.Watch(quit.watch);
  } else if (!session.empty()) {
    shell.OpenSession(session);
  } else if (!dataset.empty()) {
    shell.OpenDataset(dataset,
                      quit.fresh ? ui::ExistingSession::kStartFresh : ui::ExistingSession::kResume,
                      quit.camera);
  } else if (!quit.bag.empty()) {
    OpenBag(quit.bag);  // a file that is no recording is refused here, before a window opens
    shell.ImportRecording(quit.bag);
  }
  const int code = FinishWindow(
      shell.Run(WindowOptionsOf(width, height, "Calibench", screenshot, quit)), screenshot);
  if (!shell.error().empty()) std::fprintf(stderr, "calibench gui: %s\n", shell.error().c_str());
  return code != kOk ? code : ReportSaveFailure(shell.controller(), "gui");
}

int RunGui(int argc, char** argv) {
  CLI::App app{
      "The Calibench workbench: LiDAR image, camera frame and 3D view; brush, accept or "
      "reject pairs, solve and inspect.",
      "calibench gui"};
  std::string dataset, session, size = "1600x900", screenshot;
  GuiWindowFlags quit;
  AddDatasetOption(app, &dataset, "a LiDAR-camera or 2D LRF dataset");
  app.add_option("--session,-s", session, "a saved session (calibench.session.v1)");
  app.add_option("--bag", quit.bag,
                 "a recording (ROS 1 .bag, ROS 2 .db3 / .mcap or a rosbag2 folder): imported "
                 "behind a progress bar (as `calibench import`), then opened");
  AddBoardOption(app, &quit.board, "the board in recordings opened here");
  app.add_option("--test-drop", quit.test_drops,
                 "deliver this path to the window's drop callback after the first frames (tests)")
      ->group("");
  app.add_option("--watch", quit.watch,
                 "a folder a capture fills (camera.yaml, target.json, clouds/, images/) or a "
                 "recording being written (.bag, .mcap, .db3, a rosbag2 folder; its pairs go to "
                 "<recording>.dataset as import writes them): pairs join the list as they land, "
                 "each detected, checked and solved; the meter and the ghost board follow");
  app.add_option("--camera", quit.camera,
                 "with a rig (a folder with cameras/, or a manifest naming \"cameras\"): the "
                 "camera to open first (default: the first); the workbench switches between them");
  app.add_flag("--no-auto-solve", quit.no_auto_solve,
               "solve only on F5 / Run (by default the workbench solves once the pairs are "
               "detected and after every new or changed pair)");
  app.add_option("--screenshot-every", quit.screenshot_every_s,
                 "with --screenshot: also write a frame every S seconds to <screenshot>_<n>.png");
  app.add_option("--frame-log", quit.frame_log,
                 "write one line per frame: seconds since the start and the frame's milliseconds");
  app.add_option("--size", size, "window size WxH")->capture_default_str();
  app.add_option("--screenshot", screenshot, "write the last frame to this PNG");
  app.add_flag("--fresh", quit.fresh,
               "with --dataset: start a new session even if one is beside the dataset (the old "
               "one is kept as <session>.<date-time>.bak); by default it is resumed");
  app.add_option("--quit-after-frames", quit.after_frames,
                 "close after N frames, drawn back to back (tests)");
  app.add_option("--quit-after-seconds", quit.after_seconds,
                 "close after S seconds, drawing only on input or work as usual (tests)");
  int width = 0, height = 0;
  if (const auto code = ParseFlags(app, argc, argv, size, "gui", &width, &height)) return *code;
  if (JobKindOf(dataset, session) == JobKind::kLrf)
    return RunLrfGuiWindow(dataset, session,
                           WindowOptionsOf(width, height, "Calibench (2D LRF)", screenshot, quit),
                           screenshot, quit.fresh);
  return RunGuiWindow(dataset, session, width, height, screenshot, quit);
}

namespace {

// `render --view check`: the workbench with its targetless check window open, after the check of
// `result` (empty: the workbench's own solve, with --solve or a session's) over the dataset's
// scenes.
int RenderCheckHeadless(const std::string& dataset, const std::string& session,
                        const std::string& result, const ui::HeadlessShot& shot,
                        const std::string& out, gfx::HeadlessBackend backend) {
  const auto context = OpenHeadless(backend, "calibench render: no headless OpenGL");
  if (!context) return kInputError;
  ui::Controller controller;
  // In memory: render leaves the session beside the dataset alone.
  if (!OpenInput(controller, dataset, session, "render", ui::ExistingSession::kInMemory))
    return kUsage;
  controller.WaitIdle();
  if (!shot.pair_id.empty()) {
    const int index = ui::FindPair(controller.GetSnapshot(), shot.pair_id);
    if (index < 0) {
      std::fprintf(stderr, "calibench render: no pair %s\n", shot.pair_id.c_str());
      return kUsage;
    }
    controller.Apply(ui::SelectPair{index});
  }
  if (shot.solve) controller.Apply(ui::RunSolver{});
  controller.WaitIdle();
  controller.Apply(
      ui::RunCheck{result.empty() ? std::filesystem::path() : std::filesystem::absolute(result)});
  controller.WaitIdle();
  const ui::Snapshot checked = controller.GetSnapshot();
  if (!checked.check.report) {
    std::fprintf(stderr, "calibench render: %s\n", checked.check.failure.c_str());
    return kInputError;
  }
  const ui::HeadlessShot as_is{"", false, shot.width, shot.height};
  const auto picture = ui::RenderShot<ui::Workbench, ui::SelectPair, ui::RunSolver>(
      controller, ui::Layout::kWorkbench, as_is,
      [](ui::Workbench& workbench) { workbench.set_check_open(true); });
  const int code = SaveShot(picture, as_is, "check", out, checked.dataset_path.string(), *context);
  if (code == kOk)
    std::printf("targetless check of %s: %s\n", checked.check.checked.c_str(),
                checked.check.report->why.c_str());
  return code;
}

}  // namespace

int RenderHeadless(const std::string& dataset, const std::string& session, const std::string& pair,
                   bool solve, const std::string& view, int width, int height,
                   const std::string& out, const std::string& backend_name,
                   const std::string& save_session, bool intrinsics, const std::string& camera) {
  gfx::HeadlessBackend backend;
  const ui::HeadlessShot shot{pair, solve, width, height};
  const bool lrf = JobKindOf(dataset, "") == JobKind::kLrf;
  ui::Layout layout;
  if (!lrf && !ui::ParseLayout(view, &layout)) {
    std::fprintf(stderr,
                 "calibench render: --view must be lidar, camera, 3d, guide or workbench\n");
    return kUsage;
  }
  if (!gfx::ParseHeadlessBackend(backend_name, &backend)) {
    std::fprintf(stderr, "calibench render: --gl must be auto, egl or osmesa\n");
    return kUsage;
  }
  if (lrf) return RenderLrfHeadless(dataset, shot, view, out, backend);
  const auto context = OpenHeadless(backend, "calibench render: no headless OpenGL");
  if (!context) return kInputError;
  ui::Controller controller;
  // Render draws; it leaves session files alone (a dataset's session may be an hour of work).
  if (!OpenInput(controller, dataset, session, "render", ui::ExistingSession::kInMemory, camera))
    return kUsage;
  controller.WaitRig();  // a rig's other cameras: their frustums and meter rows
  if (intrinsics) {
    // The camera-intrinsics window over the workbench, with the estimate from the loaded pairs.
    controller.WaitIdle();
    const CameraModelType model = controller.GetSnapshot().dataset->camera.type;
    controller.Apply(ui::EstimateIntrinsics{model});
  }
  const auto picture = ui::RenderShot<ui::Workbench, ui::SelectPair, ui::RunSolver>(
      controller, layout, shot,
      [intrinsics](ui::Workbench& workbench) { workbench.set_intrinsics_open(intrinsics); });
  const int code =
      SaveShot(picture, shot, view, out, controller.GetSnapshot().dataset_path.string(), *context);
  if (code != kOk || save_session.empty()) return code;
  controller.Apply(ui::SaveSessionAs{std::filesystem::absolute(save_session)});
  if (const int saved = ReportSaveFailure(controller, "render"); saved != kOk) return saved;
  std::printf("wrote %s\n", save_session.c_str());
  return kOk;
}

int RenderDemoViews(const std::string& dataset, const std::string& out_dir) {
  const auto context = OpenHeadless(gfx::HeadlessBackend::kAuto,
                                    "calibench demo: no headless OpenGL to render the views");
  if (!context) return kInputError;
  ui::Controller controller;
  controller.OpenDataset(dataset, std::filesystem::path(out_dir) / "calibench.session.json");
  controller.WaitIdle();
  controller.Apply(ui::RunSolver{});
  controller.WaitIdle();
  ui::ImGuiHost host(nullptr);
  const struct {
    ui::Layout layout;
    const char* file;
    int width, height;
  } kViews[] = {{ui::Layout::kWorkbench, "workbench.png", 1600, 900},
                {ui::Layout::kLidarOnly, "view_lidar.png", 800, 450},
                {ui::Layout::kCameraOnly, "view_camera.png", 800, 600},
                {ui::Layout::kSceneOnly, "view_3d.png", 800, 600}};
  for (const auto& view : kViews) {
    ui::Workbench workbench;
    const std::string path = out_dir + "/" + view.file;
    SaveImage(path, ui::RenderWorkbenchHeadless(controller, workbench, host, view.layout,
                                                view.width, view.height, 4));
    std::printf("rendered %s\n", path.c_str());
  }
  if (const int code = ReportSaveFailure(controller, "demo"); code != kOk) return code;
  std::printf("session: %s/calibench.session.json (open it with `calibench gui --session ...`)\n",
              out_dir.c_str());
  return kOk;
}

int RunRender(int argc, char** argv) {
  CLI::App app{
      "Draw the workbench views to PNG without a window (EGL surfaceless or OSMesa): "
      "exactly what the window shows.",
      "calibench render"};
  std::string dataset, session, pair, view = "workbench", size = "1600x900", out, gl = "auto";
  bool solve = false;
  AddDatasetOption(app, &dataset, "a LiDAR-camera or 2D LRF dataset");
  app.add_option("--session,-s", session, "a saved session");
  app.add_option("--pair", pair, "pair id to show (default: the session's selection)");
  app.add_flag("--solve", solve, "run the solver before drawing");
  app.add_option("--view", view,
                 "lidar | camera | 3d | workbench | guide (the camera and 3D views with the ghost "
                 "board where to hold the board next, and the meter; with --solve) | check (the "
                 "workbench with its targetless check window: --result, or the workbench's solve, "
                 "checked against the scene's edges; the LiDAR's edges on the image under it and "
                 "under the estimate) (LRF datasets: scan | depth | 3d | workbench)")
      ->capture_default_str();
  app.add_option("--size", size, "WxH")->capture_default_str();
  app.add_option("--out,-o", out, "PNG file")->required();
  app.add_option("--gl", gl, "auto | egl | osmesa")->capture_default_str();
  std::string save_session;
  app.add_option("--save-session", save_session,
                 "write the session (with --solve, its result) to this file; render writes no "
                 "session otherwise and leaves the one beside the dataset alone");
  std::string camera;
  app.add_option("--camera", camera,
                 "with a rig (a folder with cameras/, or a manifest naming \"cameras\"): the "
                 "camera to draw (default: the first); the others show in the strip, the meter "
                 "and the 3D view");
  bool intrinsics = false;
  app.add_flag("--intrinsics", intrinsics,
               "LiDAR-camera: open the camera-intrinsics window, estimated from the loaded pairs "
               "(coverage map, per-image error, sigma)");
  std::string result;
  app.add_option("--result,-r", result,
                 "with --view check: the calibration to check (a result file or a session; "
                 "default: the workbench's solve)");
  int width = 0, height = 0;
  if (const auto code = ParseFlags(app, argc, argv, size, "render", &width, &height)) return *code;
  if (view == "check") {
    gfx::HeadlessBackend backend;
    if (!gfx::ParseHeadlessBackend(gl, &backend)) {
      std::fprintf(stderr, "calibench render: --gl must be auto, egl or osmesa\n");
      return kUsage;
    }
    return RenderCheckHeadless(dataset, session, result, {pair, solve, width, height}, out,
                               backend);
  }
  return RenderHeadless(dataset, session, pair, solve, view, width, height, out, gl, save_session,
                        intrinsics, camera);
}

}  // namespace calibench::app
