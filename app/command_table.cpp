#include "app/command_table.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/base/types.h"
#include "core/io/assets.h"

namespace calibench::app {

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* help;
};

constexpr Command kCommands[] = {
    {"calibrate", RunCalibrate,
     "calibrate a LiDAR to a camera from a dataset manifest; writes calibench.result.v1"},
    {"lrf-calibrate", RunLrfCalibrate,
     "calibrate a 2D laser rangefinder to a depth camera (three-face target) or an RGB camera "
     "(checkerboard)"},
    {"advise", RunAdvise,
     "is the capture enough for the goal (σ per axis, stop rule), and where to hold the board "
     "next"},
    {"check", RunCheck,
     "is a calibration still right? judged from the scene without a target: consistent, "
     "miscalibrated (with an estimate and its sigma) or cannot tell (and along which axis)"},
    {"check-sweep", RunCheckSweep,
     "the targetless check measured on simulated textured rooms: catch rates, false alarms, "
     "chi2 of its sigma"},
    {"watch", RunWatch,
     "follow a capture while it is written (a growing folder): per pair, accept/reject, σ against "
     "the goal, the next pose"},
    {"evaluate", RunEvaluate,
     "score a result against a dataset's ground truth (--subsets: is the reported σ honest?)"},
    {"simulate", RunSimulate, "write a synthetic dataset with ground truth"},
    {"demo", RunDemo, "simulate the demo dataset, calibrate it, print the error"},
    {"gui", RunGui,
     "the workbench window: brush, accept/reject pairs, solve, inspect (--dataset or --session)"},
    {"render", RunRender, "draw the workbench or one view to PNG without a window (EGL / OSMesa)"},
    {"import", RunImport,
     "turn a ROS 1 .bag or ROS 2 .db3 / .mcap recording into a dataset folder (--list: topics)"},
    {"export", RunExport,
     "write a result as URDF, ROS 1 / ROS 2 static TF, OpenCV YAML, Autoware, Kalibr or 4x4 text"},
    {"report", RunReport,
     "a self-contained HTML report of a result: both directions, sigma, per-pair residuals, "
     "held-out cross-validation, plots and views"},
    {"intrinsics", RunIntrinsics,
     "the camera's intrinsics from board images (OpenCV calibrateCamera / fisheye): RMS, sigma, "
     "coverage and the stop rule"},
    {"target", RunTarget,
     "a printable board at exact scale (PDF/SVG, 100 mm ruler) and its target.json"},
    {"sweep", RunSweep,
     "the paper's Table 1 protocol: error vs. number of pairs and noise on simulated data"},
};

void PrintUsage() {
  std::printf("usage: calibench <command> [options]   (calibench <command> --help)\n\ncommands:\n");
  for (const Command& c : kCommands) std::printf("  %-14s %s\n", c.name, c.help);
  std::printf("  %-14s %s\n", "help", "this list, or `calibench help <command>` for its flags");
  std::printf("\ncalibench --version prints the version.\n");
}

const Command* FindCommand(const char* name) {
  for (const Command& c : kCommands)
    if (std::strcmp(name, c.name) == 0) return &c;
  return nullptr;
}

// Runs a command, turning the errors that escape it into a message and an exit code.
int Run(const Command& c, int argc, char** argv) {
  try {
    return c.run(argc, argv);
  } catch (const IoError& e) {
    std::fprintf(stderr, "calibench %s: error: %s\n", c.name, e.what());
    return kInputError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "calibench %s: internal error: %s\n", c.name, e.what());
    return kInputError;
  }
}

}  // namespace

std::vector<std::string> CommandNames() {
  std::vector<std::string> names;
  for (const Command& c : kCommands) names.emplace_back(c.name);
  return names;
}

int RunCalibench(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    PrintUsage();
    return argc < 2 ? kUsage : kOk;
  }
  if (!std::strcmp(argv[1], "--version") || !std::strcmp(argv[1], "version")) {
    std::printf("calibench %s\n", CALIBENCH_VERSION);
    try {
      std::printf("assets: %s\n", FindAsset("report").parent_path().c_str());
    } catch (const IoError& e) {
      std::printf("assets: none found (%s)\n", e.what());
    }
    return kOk;
  }
  if (!std::strcmp(argv[1], "help")) {
    if (argc < 3) {
      PrintUsage();
      return kOk;
    }
    const Command* c = FindCommand(argv[2]);
    if (c == nullptr) {
      std::fprintf(stderr, "calibench help: unknown command '%s'\n", argv[2]);
      return kUsage;
    }
    char help_flag[] = "--help";
    char* help_argv[] = {argv[2], help_flag, nullptr};
    return Run(*c, 2, help_argv);
  }
  if (const Command* c = FindCommand(argv[1])) return Run(*c, argc - 1, argv + 1);
  const std::string suggestion = Closest(argv[1], CommandNames());
  std::fprintf(stderr, "calibench: unknown command '%s'%s\n\n", argv[1],
               suggestion.empty() ? "" : (" (did you mean '" + suggestion + "'?)").c_str());
  PrintUsage();
  return kUsage;
}

}  // namespace calibench::app
