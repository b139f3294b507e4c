// The report's views (core/report/report_html.h, ReportFigure): the workbench's 3D overview and,
// per pair, its camera view with the LiDAR points coloured over the image, drawn headless from the
// outcome the report already solved (controller_outcome.h): no controller, no second solve.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/undistort.h"
#include "core/lidar_camera/pipeline.h"
#include "core/report/report_html.h"
#include "ui/lidar_camera/controller_outcome.h"

namespace calibench::ui {

struct ReportFigureOptions {
  int threads = 2;  // pairs read and reprojected ahead of the drawing (>= 1)
  // The pictures (pixels) and the ImGui frames drawn for each: the camera view is complete in its
  // first frame (three gave the same pixels on the shared ACFR set); the overview gets one more.
  int overview_width = 1200, overview_height = 560;
  int pair_width = 640, pair_height = 480;
  int frames = 1;
};

// What the figures need of each pair, kept as the extraction reads its files
// (PipelineOptions::on_pair_inputs), so that no file is read twice: the cloud, and the image
// undistorted at the picture's scale (a fraction of the full image). Pairs beyond max_pairs are
// not kept (memory stays bounded; their files are read again).
class KeptPairInputs {
 public:
  KeptPairInputs(const CameraModel& camera, const ReportFigureOptions& options, int max_pairs = 64);
  // For PipelineOptions::on_pair_inputs; safe from several threads. Holds `this`.
  std::function<void(const PairEntry&, const PairInputs&)> Keeper();
  // The pair's cloud and undistorted view, when kept.
  std::optional<OutcomePair> Find(const std::string& pair_id) const;
  const Undistorter& undistorter() const { return undistorter_; }

 private:
  Undistorter undistorter_;
  int max_pairs_;
  mutable std::mutex mutex_;
  std::map<std::string, OutcomePair> kept_;
};

// The undistorted view's scale for a picture of the options' size (a little over the size shown,
// for bilinear sampling).
double FigureViewScale(const CameraModel& camera, const ReportFigureOptions& options);

// `kept` (optional): the pairs' files as the extraction read them.
// Empty with *why when there is no headless OpenGL; a pair whose files cannot be read is left
// out and named in *why (the figures of the others are kept).
std::vector<ReportFigure> DrawReportFigures(const Dataset& dataset,
                                            const CalibrationOutcome& outcome,
                                            const ReportFigureOptions& options,
                                            const KeptPairInputs* kept, std::string* why);

// A rig camera's figures: its own outcome (outcome.single[camera]) drawn as one camera's are, the
// overview with the rig's other cameras around it (this one in orange), as the workbench shows a
// rig camera. A rig of one's (RigOfOne) are its dataset's, above. `kept` as above: the files of
// this camera's pairs.
std::vector<ReportFigure> DrawReportFigures(const RigFolder& rig, const RigOutcome& outcome,
                                            size_t camera, const ReportFigureOptions& options,
                                            const KeptPairInputs* kept, std::string* why);

}  // namespace calibench::ui
