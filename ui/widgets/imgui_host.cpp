#include "ui/widgets/imgui_host.h"

// clang-format off
// gl_api.h first: it declares GL for everything below (and sets GLFW_INCLUDE_NONE).
#include "ui/gfx/gl_api.h"
#include <GLFW/glfw3.h>
// clang-format on

#include <imgui.h>

#include <filesystem>

#include "ui/gfx/framebuffer.h"

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
  if (std::filesystem::exists(kFont)) io.Fonts->AddFontFromFileTTF(kFont, 15.0f);
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
}

ImGuiHost::~ImGuiHost() {
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

void ImGuiHost::Render() {
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void ImGuiHost::DrawFrame(gfx::Framebuffer& target, int width, int height, double delta_seconds,
                          const std::function<void()>& build_frame) {
  NewFrame(width, height, delta_seconds);
  build_frame();
  target.Resize(width, height);
  target.Bind();
  target.Clear(0.06f, 0.06f, 0.07f, 1.0f);
  Render();
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
