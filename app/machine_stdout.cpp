#include "app/machine_stdout.h"

#include <unistd.h>

#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>

namespace calibench::app {

MachineStdout::MachineStdout(bool active) {
  if (!active) return;
  std::cout.flush();
  std::fflush(stdout);
  saved_stdout_ = ::dup(STDOUT_FILENO);
  if (saved_stdout_ < 0) return;  // no descriptor to spare: stdout stays as it is
  out_ = ::fdopen(saved_stdout_, "w");
  if (out_ == nullptr || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0) {
    if (out_ != nullptr)
      std::fclose(out_);  // closes saved_stdout_ too
    else
      ::close(saved_stdout_);
    saved_stdout_ = -1;
    out_ = stdout;
  }
}

MachineStdout::~MachineStdout() {
  if (saved_stdout_ < 0) return;
  std::cout.flush();
  std::fflush(stdout);  // what libraries wrote, to stderr where it belongs
  std::fflush(out_);
  ::dup2(saved_stdout_, STDOUT_FILENO);
  std::fclose(out_);
}

void MachineStdout::Print(const std::string& line) {
  // What the libraries wrote so far goes out first (to stderr), so that the streams interleave
  // in the order things happened.
  if (out_ != stdout) {
    std::cout.flush();
    std::fflush(stdout);
  }
  std::fputs(line.c_str(), out_);
  std::fputc('\n', out_);
  std::fflush(out_);
}

void EventLines::Emit(const std::string& event_json, const std::string& human) {
  if (!json_lines_) return out_.Print(human);
  nlohmann::json event = nlohmann::json::parse(event_json);
  event["time"] =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  out_.Print(event.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace calibench::app
