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

}  // namespace calibench::app
