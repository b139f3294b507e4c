#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "core/io/dataset.h"
#include "core/session/session.h"

namespace calibench::app {

int RunCalibrate(int argc, char** argv) {
  CLI::App app{
      "Calibrate a 3D LiDAR to a camera from board planes (Ca²Lib plane-to-plane "
      "Gauss-Newton with a Huber kernel).",
      "calibench calibrate"};
  std::string dataset_path, session_path, out_path, report_path;
  AddDatasetOption(app, &dataset_path, "a LiDAR-camera dataset");
  app.add_option("--session", session_path,
                 "a workbench session (calibench.session.json): its brushes, rejections and "
                 "solver choices are used, so the result is the workbench's; its dataset unless "
                 "--dataset is given");
  app.add_option("--out,-o", out_path, "result file (calibench.result.v1)");
  app.add_option("--report", report_path,
                 "also write the HTML report (as `calibench report`) of this solve");
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  std::string why;
  if (!FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench calibrate: %s\n", why.c_str());
    return kUsage;
  }
  PairEdits edits;
  if (!session_path.empty()) {
    const Session session = LoadSession(session_path);
    if (dataset_path.empty()) dataset_path = session.dataset.string();
    ApplySessionOptions(session, &flags.options);
    edits = EditsFromSession(session);
  }
  if (dataset_path.empty()) {
    std::fprintf(stderr, "calibench calibrate: give --dataset or --session\n");
    return kUsage;
  }
  const Dataset dataset = LoadDataset(dataset_path);
  CalibrationOutcome outcome;
  const int code = CalibrateAndReport(dataset, flags.options, out_path, &outcome, edits);
  if (report_path.empty() || !outcome.solution) return code;
  ReportRequest request;
  request.out_path = report_path;
  request.session_path = session_path;
  request.result_file = out_path;
  const int written = WriteReport(dataset, outcome, flags.options, request);
  return code != kOk ? code : written;
}

}  // namespace calibench::app
