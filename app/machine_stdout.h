// --json / --json-lines: stdout carries exactly the documented objects, whatever the libraries
// underneath print. OpenCV (calcEdgeSharpness's "checkerboard too small for calculation."), PCL
// and others write to file descriptor 1 with printf or std::cout; while a MachineStdout is active
// that descriptor points at stderr, and only Print writes to the real stdout, kept aside.
#pragma once

#include <cstdio>
#include <string>

namespace calibench::app {

class MachineStdout {
 public:
  // Inactive (`active` false): Print writes to stdout and nothing is redirected.
  explicit MachineStdout(bool active);
  ~MachineStdout();  // stdout is itself again
  MachineStdout(const MachineStdout&) = delete;
  MachineStdout& operator=(const MachineStdout&) = delete;

  // Writes `line` and a newline to the real stdout, flushed: one JSON object per call.
  void Print(const std::string& line);

 private:
  int saved_stdout_ = -1;    // the real stdout while active; -1 when not
  std::FILE* out_ = stdout;  // where Print writes
};

// An event stream on stdout (`--json-lines`): one JSON object per event with its "time" (Unix
// seconds), only those on stdout; or, for people, one line of words per event.
class EventLines {
 public:
  explicit EventLines(bool json_lines) : json_lines_(json_lines), out_(json_lines) {}
  // `event_json`: the event's JSON object (serialized); `human`: its line of words.
  void Emit(const std::string& event_json, const std::string& human);

 private:
  bool json_lines_;
  MachineStdout out_;
};

}  // namespace calibench::app
