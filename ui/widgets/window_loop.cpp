#include "ui/widgets/window_loop.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>

#include "core/io/image_io.h"
#include "ui/gfx/context.h"
#include "ui/gfx/framebuffer.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {

std::unique_ptr<Window> Window::Open(const WindowOptions& options, std::string* why) {
  auto context = gfx::WindowContext::Create(options.width, options.height, options.title, why);
  if (!context) return nullptr;
  return std::unique_ptr<Window>(new Window(options, std::move(context)));
}

Window::Window(const WindowOptions& options, std::unique_ptr<gfx::WindowContext> context)
    : options_(options),
      context_(std::move(context)),
      host_(std::make_unique<ImGuiHost>(context_->window())) {}

Window::~Window() = default;

std::vector<std::string> Window::TakeDroppedPaths() { return context_->TakeDroppedPaths(); }

void Window::DeliverDrop(const std::vector<std::string>& paths) { context_->DeliverDrop(paths); }

void Window::RequestClose() { context_->RequestClose(); }

namespace {
constexpr double kAnimationFrameS = 1.0 / 60;  // frame period while the workbench animates
constexpr double kIdleWakeS = 1.0;             // wakes to check for close; draws nothing
constexpr double kChangePollS = 0.1;           // wakes to poll Run's `changed`
constexpr double kTypingFrameS = 0.25;         // redraws a focused text field's cursor
constexpr int kSettleFrames = 3;  // after input or an animation: hover, popups and layout settle
constexpr double kQuietS = 1.0;   // FrameStats::quiet_frames: nothing moved for this long
using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// What a window run records besides drawing: each frame's time (FrameStats, and one line per
// frame in WindowOptions::frame_log: seconds since the start, milliseconds drawn and shown,
// "shot" when it also wrote a screenshot) and a screenshot every screenshot_every_s.
class FrameRecorder {
 public:
  FrameRecorder(const WindowOptions& options, FrameStats* stats)
      : options_(options),
        stats_(*stats),
        log_(options.frame_log.empty() ? nullptr : std::fopen(options.frame_log.c_str(), "w")) {}
  ~FrameRecorder() {
    if (log_) std::fclose(log_);
  }
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  // Writes `<screenshots_prefix>_<n>.png` when one is due; true when it did.
  bool Screenshot(const gfx::Framebuffer& target) {
    if (options_.screenshot_every_s <= 0 || SecondsSince(last_shot_) < options_.screenshot_every_s)
      return false;
    last_shot_ = Clock::now();
    SaveImage(options_.screenshots_prefix + "_" + std::to_string(++shots_) + ".png",
              target.ReadPixels());
    return true;
  }
  // A frame drawn and shown in frame_ms (the captures not counted).
  void Record(double frame_ms, bool shot) {
    stats_.max_frame_ms = std::max(stats_.max_frame_ms, frame_ms);
    if (stats_.frames > kSettleFrames && frame_ms > 50.0) ++stats_.slow_frames;
    if (log_)
      std::fprintf(log_, "%.3f %.2f%s\n", SecondsSince(start_), frame_ms, shot ? " shot" : "");
  }

 private:
  const WindowOptions& options_;
  FrameStats& stats_;
  std::FILE* log_;
  const Clock::time_point start_ = Clock::now();
  Clock::time_point last_shot_ = start_;
  int shots_ = 0;
};

}  // namespace

std::optional<ImageU8> Window::Run(const std::function<bool(int, int, double)>& frame,
                                   const std::function<bool()>& changed) {
  const auto since = SecondsSince;
  std::optional<ImageU8> last_picture;
  gfx::Framebuffer target;
  FrameRecorder recorder(options_, &stats_);
  const auto start = Clock::now();
  auto last_draw = start, last_change = start;
  const bool back_to_back = options_.quit_after_frames > 0;
  bool animating = true;  // the first frames lay the workbench out
  int settle = kSettleFrames;
  std::uint64_t seen_events = context_->EventCount();
  while (!context_->ShouldClose()) {
    const bool typing = ImGui::GetIO().WantTextInput;
    if (back_to_back || settle > 0)
      context_->PollEvents();
    else if (animating)
      context_->WaitEvents(std::max(1e-3, kAnimationFrameS - since(last_draw)));
    else
      context_->WaitEvents(typing ? std::max(1e-3, kTypingFrameS - since(last_draw))
                                  : (changed ? kChangePollS : kIdleWakeS));
    if (options_.quit_after_seconds > 0 && since(start) >= options_.quit_after_seconds) break;
    if (changed && changed()) settle = std::max(settle, 1);
    if (context_->EventCount() != seen_events) {
      seen_events = context_->EventCount();
      settle = kSettleFrames;
      last_change = Clock::now();
    }
    const bool due = back_to_back || settle > 0 ||
                     (animating && since(last_draw) >= kAnimationFrameS - 1e-3) ||
                     (typing && since(last_draw) >= kTypingFrameS);
    if (!due) continue;
    int width = 0, height = 0;
    context_->FramebufferSize(&width, &height);
    if (width <= 0 || height <= 0) {  // minimised: nothing to draw until restored
      settle = 0;
      continue;
    }
    if (stats_.frames >= kSettleFrames && !options_.test_drops.empty()) {
      DeliverDrop({options_.test_drops.front()});
      options_.test_drops.erase(options_.test_drops.begin());
    }
    const double seconds = since(last_draw);
    last_draw = Clock::now();
    if (since(last_change) >= kQuietS) ++stats_.quiet_frames;
    ++stats_.frames;
    const auto frame_start = Clock::now();
    host_->DrawFrame(target, width, height, seconds,
                     [&] { animating = frame(width, height, seconds); });
    const double frame_ms = 1e3 * since(frame_start);  // drawn; shown below (not the captures)
    animating = animating || !options_.test_drops.empty();
    if (animating) {
      settle = kSettleFrames;
      last_change = Clock::now();
    } else if (settle > 0) {
      --settle;
    }
    const bool shot = recorder.Screenshot(target);
    const bool last_frame = back_to_back && stats_.frames >= options_.quit_after_frames;
    if (options_.capture_last_frame && (last_frame || options_.quit_after_seconds > 0))
      last_picture = target.ReadPixels();
    const auto present_start = Clock::now();
    context_->Present(target);
    recorder.Record(frame_ms + 1e3 * since(present_start), shot);
    if (last_frame) break;
  }
  return last_picture;
}

}  // namespace calibench::ui
