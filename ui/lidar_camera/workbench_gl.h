// GL resources of the workbench (private to ui/lidar_camera/workbench*.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "ui/gfx/framebuffer.h"
#include "ui/gfx/renderers.h"
#include "ui/gfx/scene_layers.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/zoom_pan_image.h"

namespace calibench::ui {

// The reprojected points as shown (pixels of the image shown, turbo colours by range), kept for the
// reprojection and the image mode they were made for: a zoom, a pan or a point style needs only
// their placement again.
struct ShownReprojection {
  std::shared_ptr<const Reprojection> source;
  bool undistorted = false;
  std::vector<Vec2> pixels;
  std::vector<gfx::Rgba> colors;
};

struct Workbench::Gl {
  gfx::ImageTexture lidar_picture;
  gfx::ImageTexture camera_image;
  const ImageU8* camera_image_source = nullptr;  // what camera_image holds
  gfx::Framebuffer camera_target;
  gfx::PointRenderer camera_points;
  ShownReprojection camera_points_shown;
  gfx::Framebuffer scene_target;
  gfx::PointRenderer scene_points;
  float scene_floor_z = -1.5f;    // metres, LiDAR frame; from the shown cloud
  gfx::SceneLayers scene_layers;  // grid, frames, cloud, boards, ghost (DrawScene)
  std::map<std::string, std::unique_ptr<gfx::ImageTexture>> thumbnails;
  // The rig strip's frames by camera, with the picture each holds (they change with the capture).
  struct RigFrame {
    std::unique_ptr<gfx::ImageTexture> texture;
    const ImageU8* source = nullptr;
  };
  std::map<std::string, RigFrame> rig_frames;
  gfx::ImageTexture check_overlay;  // the check window's picture (Workbench::CheckOverlay)
};

// What the camera view shows in a frame: the raw image with the real lens, or the undistorted one
// with its pinhole, and where.
struct CameraShown {
  const ImageU8* image = nullptr;
  bool undistorted = false;
  const CameraModel* lens = nullptr;   // the camera's
  const CameraModel* model = nullptr;  // what `image` was taken with: `lens` or the pinhole
  ZoomPanImage::Placement at;

  // A raw-image pixel as shown (through the pinhole when undistorted).
  std::optional<Vec2> FromRaw(const Vec2& raw) const {
    if (!undistorted) return raw;
    const auto ray = lens->Unproject(raw);
    return ray ? model->Project(*ray) : std::nullopt;
  }
};

// A colour map's RGB with an alpha.
inline gfx::Rgba ToRgba(const std::array<std::uint8_t, 3>& rgb, std::uint8_t alpha = 255) {
  return {rgb[0], rgb[1], rgb[2], alpha};
}

}  // namespace calibench::ui
