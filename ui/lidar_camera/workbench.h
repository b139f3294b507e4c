// One frame of the workbench: the three views side by side on top (LiDAR image, camera frame,
// 3D), the measurements list and the solver panel below, a status line at the bottom. Reads a
// controller Snapshot, issues ImGui calls, returns the user's Intents. Owns only GL resources
// and view-local state (zoom, pan, replay position). Used identically by the window and by the
// headless renderer, which is what makes `calibench render` show what the window shows.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ui/gfx/framebuffer.h"
#include "ui/gfx/renderers.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {

enum class Layout { kWorkbench, kLidarOnly, kCameraOnly, kSceneOnly };
// "workbench", "lidar", "camera", "3d"; false for others.
bool ParseLayout(const std::string& name, Layout* layout);

class Workbench {
 public:
  Workbench();
  ~Workbench();
  // Call between ImGui::NewFrame() and ImGui::Render(); width/height of the display in pixels.
  // replay_seconds advances the solver replay (seconds since the last frame).
  std::vector<Intent> Frame(const Snapshot& snapshot, int width, int height, Layout layout,
                            double seconds_since_last_frame);

  // Where the last frame drew the LiDAR image (screen pixels) and which horizontal texture range
  // [u0, u1] it showed: lets tests (and tools) aim the brush at a LiDAR pixel.
  struct ImageRect {
    float x = 0, y = 0, w = 0, h = 0, u0 = 0, u1 = 1;
  };
  const ImageRect& lidar_image_rect() const { return lidar_image_rect_; }

 private:
  struct ViewRect {
    float x, y, w, h;
  };
  void LidarView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents);
  void CameraView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents);
  void SceneView(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents);
  // Draws the 3D scene (grid, axes, cloud, board quads) into gl_->scene_target.
  void DrawScene(const Snapshot& s, const PairView& pair, const gfx::Matrix4f& view_projection,
                 const Pose* estimate, int width, int height);
  void MeasurementsPanel(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents);
  void SolverPanel(const Snapshot& s, const ViewRect& r, std::vector<Intent>* intents);
  void StatusLine(const Snapshot& s, const ViewRect& r);
  void HandleKeys(const Snapshot& s, std::vector<Intent>* intents);
  const Pose* DisplayedEstimate(const Snapshot& s) const;

  // GL resources, created lazily inside a current context.
  struct Gl;
  std::unique_ptr<Gl> gl_;
  // View-local state.
  float lidar_zoom_ = 3.0f;        // horizontal zoom of the LiDAR image (1 = all 360 degrees)
  float lidar_center_ = 0.5f;      // centre column as a fraction of the image width
  std::string lidar_centered_on_;  // pair whose brush the LiDAR view was last centred on
  float camera_zoom_ = 1.0f;       // 1 = the whole image; wheel zooms about the mouse
  float camera_center_x_ = 0.5f;   // visible centre, fractions of the image
  float camera_center_y_ = 0.5f;
  double replay_position_ = -1;  // iteration shown; < 0 = the last one
  bool replaying_ = false;
  bool scene_camera_colors_ = true;  // 3D cloud coloured from the image once a solve exists
  std::string export_path_ = "result.json";
  std::string session_path_ = "session.json";
  ImageRect lidar_image_rect_;
  std::uint64_t scene_frame_key_ = 0;  // what the 3D framebuffer last showed
  std::uint64_t lidar_key_ = ~0ull, camera_key_ = ~0ull, scene_key_ = ~0ull;
};

}  // namespace calibench::ui
