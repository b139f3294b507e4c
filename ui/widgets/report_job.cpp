#include "ui/widgets/report_job.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <system_error>

namespace calibench::ui {
namespace {

std::string Quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::filesystem::path CalibenchExecutable() {
  std::error_code error;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path("calibench") : exe;
}

ReportJob::ReportJob(std::filesystem::path exe, std::filesystem::path session,
                     std::filesystem::path out)
    : out_(std::move(out)) {
  const std::string command = Quoted(exe.string()) + " report --result " +
                              Quoted(session.string()) + " --out " + Quoted(out_.string()) +
                              " 2>&1";
  thread_ = std::thread([this, command] {
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) {
      output_ = "cannot start " + command;
      done_ = true;
      return;
    }
    std::array<char, 4096> buffer{};
    size_t n = 0;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
      output_.append(buffer.data(), n);
    const int status = pclose(pipe);
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    done_ = true;
  });
}

ReportJob::~ReportJob() {
  if (thread_.joinable()) thread_.join();
}

}  // namespace calibench::ui
