#include "ui/widgets/report_runner.h"

#include <imgui.h>

#include <sstream>

namespace calibench::ui {

void ReportRunner::MenuItem(const std::filesystem::path& session, bool ready,
                            const std::string& what) {
  if (!ImGui::MenuItem("Report... (calibench_report.html beside the session)", nullptr, false,
                       ready && !session.empty() && !job_))
    return;
  // The session on disk is current: every edit and solve is autosaved.
  what_ = what;
  job_ = std::make_unique<ReportJob>(CalibenchExecutable(), session,
                                     session.parent_path() / "calibench_report.html");
}

std::string ReportRunner::Draw() {
  std::string failure;
  if (job_ && job_->Done()) {
    std::string lines;  // what the command said, without its progress
    std::istringstream output(job_->output());
    for (std::string line; std::getline(output, line);)
      if (!line.empty() && line[0] != '[') lines += line + "\n";
    message_ = job_->exit_code() == 0 ? lines : "the report failed:\n" + lines;
    if (job_->exit_code() != 0) failure = message_;
    show_ = job_->exit_code() == 0;
    job_.reset();
  }
  if (job_) {
    ImGui::SetNextWindowPos(ImVec2(8, 28));
    ImGui::Begin("##report", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::Text("writing %s (%s)...", job_->out().c_str(), what_.c_str());
    ImGui::End();
  }
  if (show_) {
    ImGui::OpenPopup("Report");
    show_ = false;
  }
  if (ImGui::BeginPopupModal("Report", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 45.0f);  // an auto-sized popup needs a width
    ImGui::TextUnformatted(message_.c_str());
    ImGui::PopTextWrapPos();
    if (ImGui::Button("OK")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
  return failure;
}

}  // namespace calibench::ui
