// One frame of the workbench (WorkbenchFrame): the three views side by side on top (LiDAR image,
// camera frame, 3D), the measurements list and the solver panel below, a status line at the
// bottom. Reads a controller Snapshot, issues ImGui calls, returns the user's Intents. Owns only GL
// resources and view-local state (zoom, pan, replay position). Used identically by the window and
// by the headless renderer, which is what makes `calibench render` show what the window shows.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ui/gfx/renderers.h"
#include "ui/gfx/scene_layers.h"
#include "ui/lidar_camera/controller.h"
#include "ui/widgets/export_row.h"
#include "ui/widgets/view_window.h"
#include "ui/widgets/workbench_frame.h"
#include "ui/widgets/zoom_pan_image.h"

namespace calibench::ui {

struct CameraShown;  // what the camera view shows in a frame (workbench_gl.h)

// kGuide: the camera and 3D views (with the ghost board) over the solver panel (with the meter).
enum class Layout { kWorkbench, kLidarOnly, kCameraOnly, kSceneOnly, kGuide };
// "workbench", "lidar", "camera", "3d", "guide"; false for others.
bool ParseLayout(const std::string& name, Layout* layout);

// The camera's viewing frustum as lines: its image border's rays, depth_m (metres) long, from the
// camera's centre, in the frame lidar_from_cam maps into.
void AddCameraFrustum(const CameraModel& camera, const Pose& lidar_from_cam, double depth_m,
                      const gfx::Rgba& color, gfx::LineBatch* lines);

class Workbench : public WorkbenchFrame<Snapshot, Intent, Layout> {
 public:
  Workbench();
  ~Workbench() override;

  // Where the last frame drew the LiDAR image (screen pixels) and which texture ranges [u0, u1]
  // and [v0, v1] it showed: lets tests (and tools) aim the brush at a LiDAR pixel.
  struct ImageRect {
    float x = 0, y = 0, w = 0, h = 0, u0 = 0, u1 = 1, v0 = 0, v1 = 1;
  };
  const ImageRect& lidar_image_rect() const { return lidar_image_rect_; }
  // Where the last frame drew the 3D view (screen pixels; u and v unused).
  const ImageRect& scene_image_rect() const { return scene_image_rect_; }
  // The 3D view's left drag paints the board on the points instead of orbiting (the "brush"
  // checkbox of its toolbar).
  void set_scene_brush(bool on) { scene_brush_ = on; }
  // The camera-intrinsics window (its button in the solver panel; `render --intrinsics`).
  void set_intrinsics_open(bool on) { intrinsics_open_ = on; }
  // The targetless check window (its button in the solver panel; `render --view check`).
  void set_check_open(bool on) { check_open_ = on; }

 private:
  // LiDAR view (workbench_lidar.cpp).
  void LidarView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents);
  void LidarToolbar(const Snapshot& s, const PairView& pair, std::vector<Intent>* intents);
  void CenterLidarOnBrush(const PairView& pair);
  void LidarPicture(const Snapshot& s, const PairView& pair, std::vector<Intent>* intents);
  // Camera view (workbench_camera.cpp).
  void CameraView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents);
  // Returns the view settings as edited this frame.
  ViewState CameraToolbar(const Snapshot& s, const PairView& pair, std::vector<Intent>* intents);
  // The image and the reprojected points into gl_->camera_target, when they changed.
  void DrawCameraTarget(const Snapshot& s, const PairView& pair, const CameraShown& shown,
                        const ViewState& view);
  // 3D view (workbench_scene.cpp).
  void SceneView(const Snapshot& s, const Rect& r, std::vector<Intent>* intents);
  void UploadSceneCloud(const Snapshot& s, const PairView& pair, bool camera_colors);
  // Draws the 3D scene (grid, axes, cloud, board quads) into gl_->scene_target.
  void DrawScene(const Snapshot& s, const PairView& pair, const gfx::Matrix4f& view_projection,
                 const Pose* estimate, int width, int height);
  // Panels (workbench_panels.cpp).
  void MeasurementsPanel(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) override;
  void PairRow(const Snapshot& s, int index, std::vector<Intent>* intents);
  void SolverPanel(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) override;
  void SolutionReadouts(const SolverView& solver, std::vector<Intent>* intents);
  // The meter: σ per axis against the goal, the weakest in words, done (workbench_meter.cpp).
  void MeterRows(const Snapshot& s, std::vector<Intent>* intents);
  void GuideRows(const Snapshot& s);  // the next pose in words, the ghost's match
  // A followed recording whose board no preset explains: why, and the board picked from a list
  // (the presets, or a target file's path) (workbench_meter.cpp).
  void BoardPicker(const Snapshot& s, std::vector<Intent>* intents);

 public:
  // A window that appeared without input (the board picker, opened by a followed capture's look) is
  // sized in its first frame and shown in the next: the window must draw that next one too.
  bool NeedsAnotherFrame() const { return picker_frames_ == 1; }

 private:
  // A rig (workbench_rig.cpp): the camera selector and the strip of the selected capture's frames
  // (measurements panel); the meter over every camera and the rig solve (solver panel); every
  // camera's frustum into the 3D view's camera layer.
  void RigStrip(const Snapshot& s, std::vector<Intent>* intents);
  void RigMeterRows(const Snapshot& s, std::vector<Intent>* intents);
  void DrawRigFrustums(const Snapshot& s, const Pose* estimate, gfx::SceneLayers::Layer* layer);
  // The camera-intrinsics window (workbench_intrinsics.cpp): estimate from the loaded pairs, the
  // coverage map, the per-image error, σ and the verdict, save beside the dataset.
  void IntrinsicsWindow(const Snapshot& s, std::vector<Intent>* intents);
  // The targetless check window (workbench_check.cpp): check the workbench's calibration or a
  // result file, the verdict, change and σ per axis, the weakest direction's cost, the selected
  // pair's LiDAR edges under both calibrations, adopt the estimate.
  void CheckWindow(const Snapshot& s, std::vector<Intent>* intents);
  void CheckOverlay(const Snapshot& s, const CheckReport& r);
  // workbench.cpp
  void View(int index, const Snapshot& s, const Rect& r, std::vector<Intent>* intents) override;
  std::string Opened(const Snapshot& s) const override;
  void HandleKeys(const Snapshot& s, std::vector<Intent>* intents) override;
  // The estimate shown: the replayed iteration, else the solution; null before a solve.
  const Pose* DisplayedEstimate(const Snapshot& s) const;

  // GL resources, made by the constructor: construct a workbench with a GL context current.
  struct Gl;
  std::unique_ptr<Gl> gl_;
  // View-local state.
  int picked_preset_ = 0;           // BoardPicker's list
  int picker_frames_ = 0;           // frames BoardPicker has been drawn in a row
  std::string picked_target_file_;  // BoardPicker's path field
  // Horizontal zoom of the LiDAR image (1 = all 360 degrees); 0 = fit the rows, drawn at the
  // sensor's angular aspect, to the view's height.
  float lidar_zoom_ = 0.0f;
  float lidar_center_ = 0.5f;        // centre column as a fraction of the image width
  float lidar_center_v_ = 0.5f;      // centre row as a fraction of the height, when cropped
  std::string lidar_centered_on_;    // pair whose brush the LiDAR view was last centred on
  ZoomPanImage camera_image_;        // zoom and pan of the camera view
  bool scene_camera_colors_ = true;  // 3D cloud coloured from the image once a solve exists
  ExportChoice export_;
  std::string session_path_ = "session.json";
  ImageRect lidar_image_rect_;
  ImageRect scene_image_rect_;
  bool scene_brush_ = false;
  int listed_selection_ = -1;  // the selection the measurements list last showed
  bool intrinsics_open_ = false;
  int intrinsics_model_ = -1;  // 0 pinhole, 1 fisheye; -1 = the dataset camera's
  int intrinsics_format_ = 0;  // ros, opencv, kalibr
  std::string intrinsics_path_ = "camera.estimated.yaml";
  bool check_open_ = false;
  std::string check_result_path_;
  bool check_show_reference_ = true, check_show_estimate_ = true;
  std::string check_overlay_key_;      // what gl_->check_overlay shows
  std::uint64_t scene_frame_key_ = 0;  // what the 3D framebuffer last showed
  std::uint64_t lidar_key_ = ~0ull, camera_key_ = ~0ull, scene_key_ = ~0ull;
};

}  // namespace calibench::ui
