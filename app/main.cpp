// calibench: one executable, a table of subcommands (COLMAP style). The GUI arrives as `gui`.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "app/commands.h"
#include "core/base/allocator.h"
#include "core/base/types.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* help;
};

constexpr Command kCommands[] = {
    {"calibrate", calibench::app::RunCalibrate,
     "calibrate a LiDAR to a camera from a dataset manifest; writes calibench.result.v1"},
    {"lrf-calibrate", calibench::app::RunLrfCalibrate,
     "calibrate a 2D laser rangefinder to a depth camera (three-face target) or an RGB camera "
     "(checkerboard)"},
    {"evaluate", calibench::app::RunEvaluate, "score a result against a dataset's ground truth"},
    {"simulate", calibench::app::RunSimulate, "write a synthetic dataset with ground truth"},
    {"demo", calibench::app::RunDemo, "simulate the demo dataset, calibrate it, print the error"},
    {"gui", calibench::app::RunGui,
     "the workbench window: brush, accept/reject pairs, solve, inspect (--dataset or --session)"},
    {"render", calibench::app::RunRender,
     "draw the workbench or one view to PNG without a window (EGL / OSMesa)"},
    {"export", calibench::app::RunExport,
     "write a result as URDF, ROS 1 / ROS 2 static TF, OpenCV YAML, Autoware, Kalibr or 4x4 text"},
    {"sweep", calibench::app::RunSweep,
     "the paper's Table 1 protocol: error vs. number of pairs and noise on simulated data"},
};

void PrintUsage() {
  std::printf("usage: calibench <command> [options]   (calibench <command> --help)\n\ncommands:\n");
  for (const Command& c : kCommands) std::printf("  %-14s %s\n", c.name, c.help);
}

}  // namespace

int main(int argc, char** argv) {
  calibench::KeepFreedMemoryForReuse();
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    PrintUsage();
    return argc < 2 ? calibench::app::kUsage : calibench::app::kOk;
  }
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const calibench::IoError& e) {
      std::fprintf(stderr, "calibench %s: error: %s\n", c.name, e.what());
      return calibench::app::kInputError;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "calibench %s: internal error: %s\n", c.name, e.what());
      return calibench::app::kInputError;
    }
  }
  std::fprintf(stderr, "calibench: unknown command '%s'\n\n", argv[1]);
  PrintUsage();
  return calibench::app::kUsage;
}
