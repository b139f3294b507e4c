#include "ui/widgets/file_browser.h"

#include <imgui.h>

#include <cstdio>

#include "core/base/types.h"

namespace calibench::ui {
namespace fs = std::filesystem;

void FileBrowser::Open(const fs::path& folder, const std::string& title) {
  std::error_code error;
  fs::path start = folder.empty() ? fs::current_path(error) : fs::absolute(folder, error);
  if (!fs::is_directory(start, error)) start = start.parent_path();
  title_ = title;
  open_ = just_opened_ = true;
  GoTo(start);
}

void FileBrowser::GoTo(const fs::path& folder) {
  folder_ = folder.lexically_normal();
  typed_ = folder_.string();
  selected_ = -1;
  try {
    entries_ = ListFolder(folder_);
    error_.clear();
  } catch (const IoError& e) {
    entries_.clear();
    error_ = e.what();
  }
}

std::optional<fs::path> FileBrowser::Choose(const fs::path& path, bool folder) {
  std::error_code error;
  if (!fs::exists(path, error)) {
    error_ = path.string() + ": no such file or folder";
    return std::nullopt;
  }
  const bool is_folder = fs::is_directory(path, error);
  if (is_folder && !folder) {
    GoTo(path);
    return std::nullopt;
  }
  open_ = false;
  ImGui::CloseCurrentPopup();
  return path;
}

std::optional<fs::path> FileBrowser::Draw() {
  if (!open_) return std::nullopt;
  if (just_opened_) {
    ImGui::OpenPopup(title_.c_str());
    just_opened_ = false;
  }
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowSize({std::min(760.0f, display.x - 40), std::min(520.0f, display.y - 40)},
                           ImGuiCond_Appearing);
  ImGui::SetNextWindowPos({display.x / 2, display.y / 2}, ImGuiCond_Appearing, {0.5f, 0.5f});
  std::optional<fs::path> chosen;
  if (!ImGui::BeginPopupModal(title_.c_str(), &open_)) return std::nullopt;
  if (ImGui::Button("Up")) GoTo(folder_.parent_path());
  ImGui::SameLine();
  char text[1024];
  std::snprintf(text, sizeof(text), "%s", typed_.c_str());
  ImGui::SetNextItemWidth(-1);
  if (ImGui::InputText("##browser_path", text, sizeof(text),
                       ImGuiInputTextFlags_EnterReturnsTrue)) {
    chosen = Choose(text, /*folder=*/false);  // a folder typed is walked into
  } else {
    typed_ = text;
  }
  const float footer = ImGui::GetFrameHeightWithSpacing() * 2;
  ImGui::BeginChild("##entries", {0, -footer}, true);
  for (int i = 0; i < static_cast<int>(entries_.size()) && !chosen; ++i) {
    const FolderEntry& entry = entries_[i];
    const std::string label = (entry.IsFolder() ? "[" + entry.name + "]" : entry.name);
    if (ImGui::Selectable(label.c_str(), selected_ == i, ImGuiSelectableFlags_AllowDoubleClick)) {
      selected_ = i;
      if (ImGui::IsMouseDoubleClicked(0)) chosen = Choose(folder_ / entry.name, /*folder=*/false);
    }
    if (entry.kind != EntryKind::kFolder) {
      ImGui::SameLine(ImGui::GetWindowContentRegionMax().x - 90);
      ImGui::TextDisabled("%s", EntryKindLabel(entry.kind));
    }
  }
  ImGui::EndChild();
  if (!error_.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", error_.c_str());
  else
    ImGui::TextDisabled(
        "datasets (folders or dataset.json), sessions, recordings (.bag .db3 .mcap)");
  const bool has_selection = selected_ >= 0 && selected_ < static_cast<int>(entries_.size());
  if (ImGui::Button("Open") && !chosen)
    chosen = has_selection ? Choose(folder_ / entries_[selected_].name,
                                    /*folder=*/entries_[selected_].Openable())
                           : Choose(folder_, /*folder=*/true);
  ImGui::SameLine();
  if (ImGui::Button("Cancel")) {
    open_ = false;
    ImGui::CloseCurrentPopup();
  }
  ImGui::EndPopup();
  return chosen;
}

}  // namespace calibench::ui
