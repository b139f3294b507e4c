#include "ui/widgets/window_loop.h"

#include <chrono>

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

std::optional<ImageU8> Window::Run(const std::function<void(int, int, double)>& frame) {
  std::optional<ImageU8> last_picture;
  gfx::Framebuffer target;
  auto last = std::chrono::steady_clock::now();
  for (int count = 0; !context_->ShouldClose(); ++count) {
    context_->PollEvents();
    int width = 0, height = 0;
    context_->FramebufferSize(&width, &height);
    if (width <= 0 || height <= 0) continue;  // minimised
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last).count();
    last = now;
    host_->DrawFrame(target, width, height, seconds, [&] { frame(width, height, seconds); });
    const bool last_frame =
        options_.quit_after_frames > 0 && count + 1 >= options_.quit_after_frames;
    if (last_frame && options_.capture_last_frame) last_picture = target.ReadPixels();
    context_->Present(target);
    if (last_frame) break;
  }
  return last_picture;
}

}  // namespace calibench::ui
