// _calibench: the command line run in-process for the Python package (python/calibench). A call
// runs exactly what `calibench <command> <flags>` runs (app/command_table.h), with the GIL
// released; what the command prints on file descriptors 1 and 2 (our printf, OpenCV's and PCL's
// own writes) is kept and handed back, so that Python decides what to show and raises the
// command's own message on failure. Progress reaches a Python callback as it happens.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_table.h"
#include "app/progress_listener.h"

namespace py = pybind11;

namespace {

// One file descriptor pointed at a temporary file while a command runs; Pause / Resume give it back
// to its owner for a moment (the Python callback's own prints reach the user's terminal).
class CapturedDescriptor {
 public:
  explicit CapturedDescriptor(int fd) : fd_(fd), file_(std::tmpfile()), saved_(dup(fd)) {
    if (file_ == nullptr || saved_ < 0)
      throw std::runtime_error(
          "calibench: cannot capture the command's output (no temporary file)");
    Resume();
  }
  CapturedDescriptor(const CapturedDescriptor&) = delete;
  CapturedDescriptor& operator=(const CapturedDescriptor&) = delete;
  ~CapturedDescriptor() {
    Pause();
    close(saved_);
    std::fclose(file_);
  }
  void Pause() { Point(saved_); }
  void Resume() { Point(fileno(file_)); }
  // Everything written so far.
  std::string Text() {
    Flush();
    std::string text;
    std::rewind(file_);
    char buffer[65536];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, file_)) > 0;) text.append(buffer, n);
    std::fseek(file_, 0, SEEK_END);
    return text;
  }

 private:
  static void Flush() {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(stdout);
    std::fflush(stderr);
  }
  void Point(int target) {
    Flush();
    dup2(target, fd_);
  }
  int fd_;
  std::FILE* file_;
  int saved_;
};

void FlushPython() {
  for (const char* stream : {"stdout", "stderr"}) {
    py::object file = py::module_::import("sys").attr(stream);
    if (!file.is_none() && py::hasattr(file, "flush")) file.attr("flush")();
  }
}

// One command at a time: the descriptors and the progress listener are the process's.
std::mutex command_mutex;

// Runs `calibench args...`; returns (exit code, stdout text, stderr text). progress(phase, done,
// total, item) is called as the command reports progress, with the GIL held; an exception it
// raises is raised once the command has ended.
py::tuple Run(const std::vector<std::string>& args, const py::object& progress) {
  FlushPython();
  std::vector<std::string> argv_strings = {"calibench"};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);

  int code = 0;
  std::string out_text, err_text;
  py::object callback_error;
  {
    py::gil_scoped_release release;
    std::lock_guard lock(command_mutex);
    CapturedDescriptor out(1), err(2);
    if (!progress.is_none()) {
      calibench::app::SetProgressListener([&](const std::string& phase, std::int64_t done,
                                              std::int64_t total, const std::string& item) {
        py::gil_scoped_acquire acquire;
        if (callback_error) return;  // the first error stands; the command runs to its end
        out.Pause();
        err.Pause();
        try {
          progress(phase, done, total, item);
          FlushPython();
        } catch (py::error_already_set& e) {
          callback_error = e.value();
        }
        out.Resume();
        err.Resume();
      });
    }
    try {
      code = calibench::app::RunCalibench(static_cast<int>(argv_strings.size()), argv.data());
    } catch (...) {
      calibench::app::SetProgressListener({});
      throw;
    }
    calibench::app::SetProgressListener({});
    out_text = out.Text();
    err_text = err.Text();
  }
  if (callback_error) {
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(callback_error.ptr())),
                    callback_error.ptr());
    throw py::error_already_set();
  }
  return py::make_tuple(code, py::bytes(out_text), py::bytes(err_text));
}

}  // namespace

PYBIND11_MODULE(_calibench, m) {
  m.doc() =
      "Calibench's command line, run in-process. Use the package `calibench`; this module is its "
      "engine.";
  m.attr("version") = CALIBENCH_VERSION;
  m.def("run", &Run, py::arg("args"), py::arg("progress") = py::none(),
        "run(args, progress=None) -> (exit_code, stdout: bytes, stderr: bytes)\n\n"
        "Runs `calibench *args` in this process with the GIL released. progress(phase, done, "
        "total, item) is called as the command advances.");
  m.def("commands", &calibench::app::CommandNames, "The subcommands' names.");
}
