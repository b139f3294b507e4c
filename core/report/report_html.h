// The calibration report as one self-contained HTML file: styles, scripts (Debian's Chart.js,
// inlined) and pictures (data: URIs) inside, so that it opens anywhere without a network.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/lidar_camera/rig.h"
#include "core/report/calibration_report.h"

namespace calibench {

// A picture in the report: the workbench's views drawn headless (ui/), as PNG or JPEG bytes.
struct ReportFigure {
  std::string title;
  std::string pair_id;  // the pair it shows; "" for an overview
  std::string bytes;    // the encoded image
  std::string mime;     // "image/png" or "image/jpeg"
};

// Where the report's data came from: what a reviewer needs to find it again.
struct ReportProvenance {
  std::string source;       // the dataset, folder, recording or session
  std::string result_file;  // "" when the report comes with the solve itself
  std::string created_utc;  // ISO 8601
  std::string calibench_version;
  std::vector<std::string> notes;  // shown at the top (e.g. the result differs from a re-solve)
};

// The report's template, style and scripts (assets/report/) and Chart.js.
struct ReportAssets {
  std::string html_template;  // placeholders {{title}} {{style}} {{chart_js}} {{data}}
                              // {{script}} {{body}}
  std::string style;
  std::string script;  // draws the plots from the data
  std::string chart_js;
};

// Reads report.html, report.css and report.js from `report_dir` and Chart.js from `chart_js`
// (Debian's libjs-chart.js). Throws IoError naming the missing file and the package.
ReportAssets LoadReportAssets(
    const std::filesystem::path& report_dir,
    const std::filesystem::path& chart_js = "/usr/share/javascript/chart.js/chart.min.js");

// `extra_sections`: HTML sections appended after the camera's (the targetless check's,
// core/report/targetless_section.h).
std::string ReportHtml(const CalibrationReport& report, const ReportProvenance& provenance,
                       const std::vector<ReportFigure>& figures, const ReportAssets& assets,
                       const std::string& extra_sections = "");

// A rig's report: the rig solve per camera (its pose and σ next to the camera's own) and the
// cameras' relative poses, then each camera's section as one camera's report has it.
struct RigReportSummary {
  struct Camera {
    std::string name;
    int pairs = 0;
    Pose cam_from_lidar = Pose::Identity();  // the rig solve's
    Vec3 sigma_t_mm = Vec3::Zero(), sigma_r_deg = Vec3::Zero();
    Pose single_cam_from_lidar = Pose::Identity();  // the camera alone
    Vec3 single_sigma_t_mm = Vec3::Zero(), single_sigma_r_deg = Vec3::Zero();
  };
  std::vector<Camera> cameras;
  std::vector<PoseWithSigmas> relative;  // RigRelativePoses
  int shared_captures = 0;
};
// The rig's summary from its outcome: per camera, the joint solve's pose and σ beside the
// camera's own, the accepted pairs; the cameras' relative poses; the captures they share.
// Requires outcome.joint.
RigReportSummary SummarizeRigOutcome(const RigOutcome& outcome);
struct RigCameraReport {
  std::string name;
  std::string prefix;  // of its section's ids ("cam0-"): unique per camera
  CalibrationReport report;
  std::vector<ReportFigure> figures;
};
std::string RigReportHtml(const RigReportSummary& rig, const std::vector<RigCameraReport>& cameras,
                          const ReportProvenance& provenance, const ReportAssets& assets);

// Where more poses would help, in words: the cells of a 3 x 3 image grid ("top left" ... "bottom
// right") where no board centre lies, and a LiDAR field the boards span narrowly (azimuth or
// elevation under 20 degrees). "" when the boards cover both.
std::string CoverageGaps(const CalibrationReport& report);

}  // namespace calibench
