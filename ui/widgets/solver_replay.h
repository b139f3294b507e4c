// Replaying a solve iteration by iteration, as both workbenches offer it: which iteration the
// views show, the Run / Step / Replay / Reset buttons and the plot of the cost per iteration.
#pragma once

#include <imgui.h>

#include <cstddef>
#include <vector>

#include "core/estimation/uncertainty.h"

namespace calibench::ui {

class SolverReplay {
 public:
  // What the buttons ask of the controller this frame.
  struct Request {
    bool run = false;    // run the solver (Run, or Step before any solve)
    bool reset = false;  // forget the solve
  };

  // Moves a running replay on by 2 iterations per second; call once a frame.
  void Advance(size_t iterations, double seconds_since_last_frame);
  // Whether a replay is running (the views change from frame to frame).
  bool playing() const { return playing_; }
  // The index of the iteration shown: the replayed one, else the last; -1 when there is none.
  int Shown(size_t iterations) const;
  // The estimate the views show: the shown iteration's (IterationReport names it
  // cam_from_lidar for either method), else `solution` (null before a solve).
  const Pose* ShownEstimate(const std::vector<IterationReport>& iterations,
                            const Pose* solution) const;
  // The four buttons (disabled while the solver runs), on one line.
  Request Buttons(size_t iterations, bool solver_running);
  // log10 of the cost per iteration, the shown one named in the overlay; `size` in pixels.
  // Requires a non-empty `iterations`.
  void CostPlot(const std::vector<IterationReport>& iterations, ImVec2 size) const;

 private:
  double position_ = -1;  // iteration shown, fractional while replaying; < 0 = the last one
  bool playing_ = false;
};

}  // namespace calibench::ui
