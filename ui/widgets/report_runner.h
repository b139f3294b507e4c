// File → Report… in either workbench: `calibench report` on the open session (ReportJob, its own
// process: the report is exactly the command line's), a note while it runs and a popup with what
// the command said once it is done.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "ui/widgets/report_job.h"

namespace calibench::ui {

class ReportRunner {
 public:
  // The File menu's item: enabled when `ready` (a solved session, saved) and no report runs; on
  // click, writes calibench_report.html beside `session`. `what` says what the report re-solves
  // ("each pair left out, drawing the views").
  void MenuItem(const std::filesystem::path& session, bool ready, const std::string& what);
  // Every frame: the note while it runs, then the popup. Returns the failure's text once, when
  // the command failed (the shell shows it as its error), "" otherwise.
  std::string Draw();
  bool Running() const { return job_ != nullptr; }

 private:
  std::unique_ptr<ReportJob> job_;
  std::string what_;
  std::string message_;  // the last report's outcome, shown once in a popup
  bool show_ = false;
};

}  // namespace calibench::ui
