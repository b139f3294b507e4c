// One frame of the 2D LRF workbench (WorkbenchFrame; the LRF counterpart of
// ui/lidar_camera/workbench.h): the scan as a top-down plot, the depth image (or, for the
// checkerboard case, the RGB image) and the 3D view side by side on top, the measurements list
// and the solver panel below, a status line at the bottom. Reads an LrfSnapshot, issues ImGui
// calls, returns the user's LrfIntents. Owns only GL resources and view-local state (zoom, orbit,
// replay position); the window and the headless renderer use it identically.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "ui/gfx/renderers.h"
#include "ui/lrf/controller.h"
#include "ui/widgets/orbit_camera.h"
#include "ui/widgets/view_window.h"
#include "ui/widgets/workbench_frame.h"
#include "ui/widgets/zoom_pan_image.h"

namespace calibench::ui {

enum class LrfLayout { kWorkbench, kScanOnly, kDepthOnly, kSceneOnly };
// "workbench", "scan", "depth", "3d"; false for others.
bool ParseLrfLayout(const std::string& name, LrfLayout* layout);

class LrfWorkbench : public WorkbenchFrame<LrfSnapshot, LrfIntent, LrfLayout> {
 public:
  LrfWorkbench();
  ~LrfWorkbench() override;

 private:
  void ScanView(const LrfSnapshot& s, const Rect& r);
  void ImageView(const LrfSnapshot& s, const Rect& r);
  // The depth picture or the camera image of the pair into gl_->picture, when it changed.
  void UploadPicture(const LrfSnapshot& s, const LrfPairFeatures& pair, const void* source);
  void SceneView(const LrfSnapshot& s, const Rect& r);
  // The depth frame back-projected into gl_->cloud_points; the scene's centre and floor.
  void UploadDepthCloud(const LrfPairFeatures& pair);
  // Draws the 3D scene (grid, depth cloud, board, scan at the estimate, axes) into the view's
  // framebuffer.
  void DrawScene(const LrfSnapshot& s, const LrfPairFeatures& pair,
                 const gfx::Matrix4f& view_projection, const Pose* estimate, int tw, int th);
  void View(int index, const LrfSnapshot& s, const Rect& r,
            std::vector<LrfIntent>* intents) override;
  void MeasurementsPanel(const LrfSnapshot& s, const Rect& r,
                         std::vector<LrfIntent>* intents) override;
  void SolverPanel(const LrfSnapshot& s, const Rect& r, std::vector<LrfIntent>* intents) override;
  void SolutionReadouts(const LrfSnapshot& s, std::vector<LrfIntent>* intents);
  std::string Opened(const LrfSnapshot& s) const override;
  void HandleKeys(const LrfSnapshot& s, std::vector<LrfIntent>* intents) override;
  // The estimate shown: the replayed iteration, else the solution; null before a solve.
  const Pose* DisplayedEstimate(const LrfSnapshot& s) const;

  // GL resources, made by the constructor: construct a workbench with a GL context current.
  struct Gl;
  std::unique_ptr<Gl> gl_;
  float scan_zoom_ = 1.0f;  // 1 = the LRF origin and the target fit the view; wheel zooms
  ZoomPanImage image_;      // zoom and pan of the depth (or camera) image
  // 3D orbit about the target, camera frame (y down): yaw about -y, pitch down positive; the
  // distance is a multiple of the target's.
  OrbitCamera<float> orbit_{-0.75f, 0.45f, 1.6f};
  std::string export_path_ = "lrf_result.json";
  std::uint64_t image_key_ = ~0ull, scene_key_ = ~0ull;
};

}  // namespace calibench::ui
