// What both workbenches are: one frame of three views side by side on top, the measurements list
// and the solver panel below and a status line at the bottom (or one view alone, see
// workbench_layout.h), with the solver replay moving on with time. A workbench fills in each
// part; the panels read a Snapshot and return the user's Intents.
#pragma once

#include <string>
#include <vector>

#include "ui/widgets/solver_replay.h"
#include "ui/widgets/status_line.h"
#include "ui/widgets/view_window.h"
#include "ui/widgets/workbench_layout.h"

namespace calibench::ui {

template <typename Snapshot, typename Intent, typename Layout>
class WorkbenchFrame {
 public:
  virtual ~WorkbenchFrame() = default;

  // Call between ImGui::NewFrame() and ImGui::Render(); width/height of the display in pixels;
  // seconds_since_last_frame advances the solver replay.
  // Whether the next frame will look different without any input: the worker is busy (progress,
  // results on their way) or a replay runs. The window redraws only then, or on input.
  bool Animating(const Snapshot& s) const { return s.busy || replay_.playing(); }

  // top: pixels above the frame taken by the window's menu bar.
  std::vector<Intent> Frame(const Snapshot& s, int width, int height, Layout layout,
                            double seconds_since_last_frame, float top = 0.0f) {
    std::vector<Intent> intents;
    replay_.Advance(s.solver.iterations.size(), seconds_since_last_frame);
    const FrameRects frame = ArrangeFrame(static_cast<int>(layout), width, height, shares_, top);
    for (int view = 0; view < 3; ++view)
      if (frame.Shows(view)) View(view, s, frame.views[view], &intents);
    if (!frame.panels()) return intents;
    if (frame.measurements_shown()) MeasurementsPanel(s, frame.measurements, &intents);
    SolverPanel(s, frame.solver, &intents);
    StatusLine(frame.status, s.busy, s.status_is_error, s.status_line, Opened(s));
    HandleKeys(s, &intents);
    return intents;
  }

 protected:
  // shares: the proportions of the frame (LoadLayoutShares: assets/workbench/layout.json).
  explicit WorkbenchFrame(const LayoutShares& shares) : shares_(shares) {}
  SolverReplay& replay() { return replay_; }
  const SolverReplay& replay() const { return replay_; }

 private:
  // View `index` (0, 1, 2: left to right) at `r`.
  virtual void View(int index, const Snapshot& s, const Rect& r, std::vector<Intent>* intents) = 0;
  virtual void MeasurementsPanel(const Snapshot& s, const Rect& r,
                                 std::vector<Intent>* intents) = 0;
  virtual void SolverPanel(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) = 0;
  // What is open, on the right of the status line (e.g. "session: work.session.json").
  virtual std::string Opened(const Snapshot& s) const = 0;
  // Keyboard shortcuts; called in the whole-workbench layout only.
  virtual void HandleKeys(const Snapshot& s, std::vector<Intent>* intents) = 0;

  SolverReplay replay_;
  LayoutShares shares_;
};

}  // namespace calibench::ui
