// The report's views (core/report/report_html.h, ReportFigure): the workbench's 3D overview and,
// per pair, its camera view with the LiDAR points coloured over the image, drawn headless from the
// outcome the report already solved (controller_outcome.h): no controller, no second solve.
#pragma once

#include <string>
#include <vector>

#include "core/lidar_camera/pipeline.h"
#include "core/report/report_html.h"

namespace calibench::ui {

struct ReportFigureOptions {
  int threads = 2;  // pairs read and reprojected ahead of the drawing (>= 1)
  // The pictures (pixels) and the ImGui frames drawn for each: the camera view is complete in its
  // first frame (three gave the same pixels on the shared ACFR set); the overview gets one more.
  int overview_width = 1200, overview_height = 560;
  int pair_width = 640, pair_height = 480;
  int frames = 1;
};

// Empty with *why when there is no headless OpenGL; a pair whose files cannot be read is left
// out and named in *why (the figures of the others are kept).
std::vector<ReportFigure> DrawReportFigures(const Dataset& dataset,
                                            const CalibrationOutcome& outcome,
                                            const ReportFigureOptions& options, std::string* why);

}  // namespace calibench::ui
