#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/io/dataset.h"

namespace calibench::app {

int RunCalibrate(int argc, char** argv) {
  CLI::App app{
      "Calibrate a 3D LiDAR to a camera from board planes (Ca²Lib plane-to-plane "
      "Gauss-Newton with a Huber kernel).",
      "calibench calibrate"};
  std::string dataset_path, out_path;
  app.add_option("--dataset,-d", dataset_path, "dataset.json or dataset folder")->required();
  app.add_option("--out,-o", out_path, "result file (calibench.result.v1)");
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  std::string why;
  if (!FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench calibrate: %s\n", why.c_str());
    return kUsage;
  }
  const Dataset dataset = LoadDataset(dataset_path);
  return CalibrateAndReport(dataset, flags.options, out_path);
}

}  // namespace calibench::app
