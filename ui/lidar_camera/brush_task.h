// The brush on a pair's LiDAR image (a task of the controller, ui/lidar_camera/controller.h): a
// stroke's dabs, the points a pick painted, the brush cleared, the board detected again. Each
// change goes to the job's record first (CalibrationJob::SetBrush; a stroke's later dabs amend
// its one undo step), then the view shows the record and the pair is refitted on the worker
// (Controls). No GL, GLFW or ImGui.
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "core/session/calibration_job.h"
#include "ui/lidar_camera/controller_snapshot.h"
#include "ui/lidar_camera/intents.h"

namespace calibench::ui {

class BrushTask {
 public:
  // What the controller does after a brush edit (mutex held).
  struct Controls {
    std::function<CalibrationJob*()> job;  // the open dataset's job
    std::function<void()> edited;          // the record shown (Publish), then the autosave
    std::function<void(int)> refit;        // pair `index`'s board fitted again, on the worker
  };
  BrushTask(TaskHost<Snapshot> host, Controls controls)
      : host_(host), controls_(std::move(controls)) {}

  // With the controller's mutex held; a pair without its LiDAR image yet is left alone.
  void Paint(const BrushStroke& stroke);
  void Paint(const PaintPoints& points);
  void Clear(const ClearBrush& clear);  // erased: no board until painted again
  // The brushes forgotten (one pair's or all, one undo step): the board detected again.
  void DetectAgain(const DetectBoardAgain& again);
  // Any intent but a dab ends the stroke: the next dab is an undo step of its own.
  void EndStroke() { stroke_open_ = false; }

 private:
  const LidarImage* ImageOf(int index) const;
  // Adds (or, erasing, removes) LiDAR-image pixels to the pair's brush.
  void Merge(int index, const std::vector<int>& pixels, bool erase);
  // The pair's brush into the job's record: an undo step, or the current one amended.
  void SetBrush(int index, std::vector<int> pixels, bool amend);

  TaskHost<Snapshot> host_;
  Controls controls_;
  bool stroke_open_ = false;  // dabs since the last EndStroke
};

}  // namespace calibench::ui
