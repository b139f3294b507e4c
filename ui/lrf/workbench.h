// One frame of the 2D LRF workbench (the LRF counterpart of ui/workbench.h): the scan as a
// top-down plot, the depth image (or, for the checkerboard case, the RGB image) and the 3D view
// side by side on top, the measurements list and the solver panel below, a status line at the
// bottom. Reads an LrfSnapshot, issues ImGui calls, returns the user's LrfIntents. Owns only GL
// resources and view-local state (zoom, orbit, replay position); the window and the headless
// renderer use it identically.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "ui/gfx/renderers.h"
#include "ui/lrf/controller.h"
#include "ui/widgets/imgui_host.h"

namespace calibench::ui {

enum class LrfLayout { kWorkbench, kScanOnly, kDepthOnly, kSceneOnly };
// "workbench", "scan", "depth", "3d"; false for others.
bool ParseLrfLayout(const std::string& name, LrfLayout* layout);

class LrfWorkbench {
 public:
  LrfWorkbench();
  ~LrfWorkbench();
  // Call between ImGui::NewFrame() and ImGui::Render(); width/height of the display in pixels;
  // seconds_since_last_frame advances the solver replay.
  std::vector<LrfIntent> Frame(const LrfSnapshot& snapshot, int width, int height, LrfLayout layout,
                               double seconds_since_last_frame);

 private:
  struct ViewRect {
    float x, y, w, h;
  };
  void ScanView(const LrfSnapshot& s, const ViewRect& r);
  void ImageView(const LrfSnapshot& s, const ViewRect& r);
  void SceneView(const LrfSnapshot& s, const ViewRect& r);
  // Draws the 3D scene (grid, depth cloud, board, scan at the estimate, axes) into the view's
  // framebuffer.
  void DrawScene(const LrfSnapshot& s, const LrfPairFeatures& pair,
                 const gfx::Matrix4f& view_projection, const Pose* estimate, int tw, int th);
  void MeasurementsPanel(const LrfSnapshot& s, const ViewRect& r, std::vector<LrfIntent>* intents);
  void SolverPanel(const LrfSnapshot& s, const ViewRect& r, std::vector<LrfIntent>* intents);
  void StatusLine(const LrfSnapshot& s, const ViewRect& r);
  void HandleKeys(const LrfSnapshot& s, std::vector<LrfIntent>* intents);
  // The estimate shown: the replayed iteration, else the solution; null before a solve.
  const Pose* DisplayedEstimate(const LrfSnapshot& s) const;

  struct Gl;  // GL resources, created lazily inside a current context
  std::unique_ptr<Gl> gl_;
  float scan_zoom_ = 1.0f;   // 1 = the LRF origin and the target fit the view; wheel zooms
  float image_zoom_ = 1.0f;  // 1 = the whole image; wheel zooms about the mouse
  float image_center_x_ = 0.5f, image_center_y_ = 0.5f;  // fractions of the image
  // 3D orbit about the target, camera frame (y down): yaw about -y, pitch down positive.
  float orbit_yaw_rad_ = -0.75f, orbit_pitch_rad_ = 0.45f, orbit_distance_scale_ = 1.6f;
  double replay_position_ = -1;  // iteration shown; < 0 = the last one
  bool replaying_ = false;
  std::string export_path_ = "lrf_result.json";
  std::uint64_t image_key_ = ~0ull, scene_key_ = ~0ull;
};

}  // namespace calibench::ui
