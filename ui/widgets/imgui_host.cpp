#include "ui/widgets/imgui_host.h"

// clang-format off
// gl_api.h first: it declares GL for everything below (and sets GLFW_INCLUDE_NONE).
#include "ui/gfx/gl_api.h"
#include <GLFW/glfw3.h>
// clang-format on

#include <imgui.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "ui/gfx/framebuffer.h"
#include "ui/gfx/texture_versions.h"
#include "ui/widgets/redraw_regions.h"

// Debian's ImGui backends, compiled in third_party/imgui with our GL loader.
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

namespace calibench::ui {

void ApplyThemeAndFont() {
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 0.0f;
  style.FrameRounding = 3.0f;
  style.WindowPadding = ImVec2(6, 6);
  style.ItemSpacing = ImVec2(6, 4);
  style.Colors[ImGuiCol_WindowBg] = ImVec4(0.11f, 0.11f, 0.13f, 1.0f);
  style.Colors[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.22f, 0.32f, 1.0f);
  style.Colors[ImGuiCol_TitleBg] = ImVec4(0.16f, 0.22f, 0.32f, 1.0f);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // layout comes from code, not from imgui.ini
  const char* kFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  // Latin-1, Greek (σ in the core's messages), punctuation (— …), arrows and math (≤ ²): what the
  // words from core/ use; ImGui's default range is Latin-1 alone and shows '?' for the rest.
  static const ImWchar kRanges[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2010, 0x205E,
                                    0x2190, 0x21FF, 0x2200, 0x22FF, 0};
  if (std::filesystem::exists(kFont)) io.Fonts->AddFontFromFileTTF(kFont, 15.0f, nullptr, kRanges);
}

ImGuiHost::ImGuiHost(GLFWwindow* window) : windowed_(window != nullptr) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ApplyThemeAndFont();
  ImGuiIO& io = ImGui::GetIO();
  if (windowed_) {
    ImGui_ImplGlfw_InitForOpenGL(window, true);
  } else {
    // The same key codes as the GLFW backend, so the panels see identical input.
    io.KeyMap[ImGuiKey_Tab] = GLFW_KEY_TAB;
    io.KeyMap[ImGuiKey_LeftArrow] = GLFW_KEY_LEFT;
    io.KeyMap[ImGuiKey_RightArrow] = GLFW_KEY_RIGHT;
    io.KeyMap[ImGuiKey_UpArrow] = GLFW_KEY_UP;
    io.KeyMap[ImGuiKey_DownArrow] = GLFW_KEY_DOWN;
    io.KeyMap[ImGuiKey_Enter] = GLFW_KEY_ENTER;
    io.KeyMap[ImGuiKey_Escape] = GLFW_KEY_ESCAPE;
    io.KeyMap[ImGuiKey_Backspace] = GLFW_KEY_BACKSPACE;
  }
  ImGui_ImplOpenGL3_Init("#version 330 core");
  // Repainting regions gathers every window's draw list into one, whose commands then index
  // vertices past 65535: the backend must apply VtxOffset (GL >= 3.2, which we create).
  if (!(io.BackendFlags & ImGuiBackendFlags_RendererHasVtxOffset))
    throw std::runtime_error(
        "ImGui's OpenGL3 backend found no glDrawElementsBaseVertex (GL < 3.2)");
  regions_ = std::make_unique<RedrawRegions>([](ImTextureID texture) {
    return gfx::TextureVersion(
        static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(texture)));
  });
  region_redraw_ = std::make_unique<RegionRedraw>();
}

ImGuiHost::~ImGuiHost() {
  region_redraw_.reset();  // its draw list belongs to the context
  ImGui_ImplOpenGL3_Shutdown();
  if (windowed_) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void ImGuiHost::NewFrame(int width, int height, double delta_seconds) {
  ImGui_ImplOpenGL3_NewFrame();
  if (windowed_) {
    ImGui_ImplGlfw_NewFrame();
  } else {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DeltaTime = static_cast<float>(delta_seconds > 0 ? delta_seconds : 1.0 / 60.0);
  }
  ImGui::NewFrame();
}

void ImGuiHost::DrawFrame(gfx::Framebuffer& target, int width, int height, double delta_seconds,
                          const std::function<void()>& build_frame) {
  constexpr float kBackground[4] = {0.06f, 0.06f, 0.07f, 1.0f};
  NewFrame(width, height, delta_seconds);
  build_frame();
  target.Resize(width, height);
  // Anything else drawn into the target since (or a new target that reuses the texture's name)
  // left another version: repaint everything.
  if (!repaint_only_changes_ || target.color_texture() != drawn_texture_ ||
      gfx::TextureVersion(target.color_texture()) != drawn_version_)
    regions_->Forget();
  target.Bind();
  ImGui::Render();
  const ImDrawData& draw_data = *ImGui::GetDrawData();
  std::vector<PixelBox> regions = regions_->Update(draw_data);
  const ImDrawData* redraw = region_redraw_->Compose(draw_data, regions);
  if (!redraw) {  // user callbacks: drawn whole, and nothing assumed of this frame next time
    regions = {WholeFramebuffer(draw_data)};
    regions_->Forget();
  }
  // Each region starts from the background, as a whole frame does.
  glEnable(GL_SCISSOR_TEST);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], kBackground[3]);
  last_repainted_pixels_ = 0;
  for (const PixelBox& region : regions) {
    glScissor(region.x, region.y, region.width, region.height);
    glClear(GL_COLOR_BUFFER_BIT);
    last_repainted_pixels_ += region.Area();
  }
  glDisable(GL_SCISSOR_TEST);
  if (!regions.empty())
    ImGui_ImplOpenGL3_RenderDrawData(redraw ? const_cast<ImDrawData*>(redraw)
                                            : ImGui::GetDrawData());
  drawn_texture_ = target.color_texture();
  drawn_version_ = gfx::TextureVersion(drawn_texture_);
}

ImageU8 RenderFramesHeadless(ImGuiHost& host, int width, int height, int frames,
                             const std::function<void()>& build_frame) {
  gfx::Framebuffer target;
  for (int frame = 0; frame < frames; ++frame)
    host.DrawFrame(target, width, height, 1.0 / 60.0, build_frame);
  glFinish();
  return target.ReadPixels();
}

}  // namespace calibench::ui
