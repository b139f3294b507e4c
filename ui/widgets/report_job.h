// File → Report… in the workbench: `calibench report` on the open session, run as its own process
// on a thread, so the window stays responsive and the report is exactly the command line's (one
// pipeline, not a copy of it in ui/).
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <thread>

namespace calibench::ui {

class ReportJob {
 public:
  // Starts `exe report --result <session> --out <out>` (exe: the calibench executable).
  ReportJob(std::filesystem::path exe, std::filesystem::path session, std::filesystem::path out);
  ~ReportJob();  // waits for the process
  ReportJob(const ReportJob&) = delete;
  ReportJob& operator=(const ReportJob&) = delete;

  bool Done() const { return done_; }
  // Once Done(): the exit code (0 = written) and what the command printed.
  int exit_code() const { return exit_code_; }
  const std::string& output() const { return output_; }
  const std::filesystem::path& out() const { return out_; }

 private:
  std::filesystem::path out_;
  std::string output_;
  int exit_code_ = -1;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

// The calibench executable this process runs as (/proc/self/exe).
std::filesystem::path CalibenchExecutable();

}  // namespace calibench::ui
