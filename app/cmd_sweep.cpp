// `calibench sweep`: the paper's Table 1 protocol (core/evaluation/plane_sweep.h) from the command
// line.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <sstream>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/evaluation/plane_sweep.h"
#include "core/lidar_camera/pipeline.h"

namespace calibench::app {
namespace {

std::vector<double> ParseList(const std::string& text) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) values.push_back(std::stod(item));
  return values;
}

}  // namespace

int RunSweep(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--guided") return RunSweepGuided(argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--kind" || std::string(argv[i]).rfind("--kind=", 0) == 0)
      return RunSweepLrf(argc, argv);
  CLI::App app{"Error vs. number of pairs and LiDAR noise (Ca²Lib Table 1 protocol).",
               "calibench sweep"};
  app.footer(
      "The 2D laser rangefinder kind: `calibench sweep --kind lrf` gives errors against the "
      "number of observations (the LRF paper's Section 4.3 protocol), with --sizes (default "
      "2,3,4,6,8,10,15,20), --seeds N (simulations per size, default 20), --preset paper|ideal, "
      "--threads, --table FILE. `calibench sweep --kind lrf --help` shows them. "
      "Guided capture against random placement: `calibench sweep --guided --help`.");
  std::string work_dir = "out/sweep", sizes_text = "3,4,5,10,20,30,39",
              noise_text = "0,0.008,0.016", image_noise_text = "0,0.007,0.014", table_path;
  int subsets = 40;
  std::string methods_text = "weighted-ml,ca2lib-gn,kim";
  app.add_option("--work-dir", work_dir, "where the simulated pools are written")
      ->capture_default_str();
  app.add_option("--sizes", sizes_text, "numbers of pairs N")->capture_default_str();
  app.add_option("--subsets", subsets, "random subsets per N")->capture_default_str();
  app.add_option("--noise-levels", noise_text, "LiDAR range noise levels [m]")
      ->capture_default_str();
  app.add_option("--image-noise-levels", image_noise_text, "image noise per level, [0,1] units")
      ->capture_default_str();
  app.add_option("--table", table_path, "also write the markdown table here");
  app.add_option("--methods", methods_text, "solvers to compare (weighted-ml, ca2lib-gn, kim)")
      ->capture_default_str();
  SimFlags sim_flags;
  sim_flags.preset = "paper";
  AddSimFlags(app, sim_flags);
  PipelineFlags flags;
  AddPipelineFlags(app, flags, /*with_selection=*/false);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  PlaneSweepOptions sweep;
  sweep.subsets = subsets;
  sweep.work_dir = work_dir;
  std::string why;
  try {
    sweep.sizes.clear();
    for (double n : ParseList(sizes_text)) sweep.sizes.push_back(static_cast<int>(n));
    sweep.range_noise_m = ParseList(noise_text);
    sweep.image_noise = ParseList(image_noise_text);
  } catch (const std::exception&) {
    std::fprintf(stderr,
                 "calibench sweep: --sizes/--noise-levels/--image-noise-levels take "
                 "comma-separated numbers\n");
    return kUsage;
  }
  sweep.methods.clear();
  std::stringstream names(methods_text);
  for (std::string name; std::getline(names, name, ',');) {
    const auto method = ParseSolverMethod(name);
    if (!method) {
      std::fprintf(stderr, "calibench sweep: unknown method '%s' in --methods\n", name.c_str());
      return kUsage;
    }
    sweep.methods.push_back(*method);
  }
  if (!FinalizePipelineFlags(flags, &why) || !BuildSimOptions(sim_flags, &sweep.sim, &why)) {
    std::fprintf(stderr, "calibench sweep: %s\n", why.c_str());
    return kUsage;
  }
  sweep.pipeline = flags.options;
  if (!sweep.Check(&why)) {
    std::fprintf(stderr, "calibench sweep: %s\n", why.c_str());
    return kUsage;
  }
  const PlaneSweepResult result = RunPlaneSweep(
      sweep, [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  return PrintAndWriteTable(FormatPlaneSweepTable(result), table_path, "calibench sweep");
}

}  // namespace calibench::app
