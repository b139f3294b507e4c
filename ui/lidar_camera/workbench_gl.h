// GL resources of the workbench (private to ui/workbench*.cpp).
#pragma once

#include <map>
#include <memory>
#include <string>

#include "ui/gfx/framebuffer.h"
#include "ui/gfx/renderers.h"
#include "ui/lidar_camera/workbench.h"

namespace calibench::ui {

struct Workbench::Gl {
  gfx::ImageTexture lidar_picture;
  gfx::ImageTexture camera_image;
  const ImageU8* camera_image_source = nullptr;  // what camera_image holds
  gfx::Framebuffer camera_target;
  gfx::PointRenderer camera_points;
  gfx::Framebuffer scene_target;
  gfx::PointRenderer scene_points;
  float scene_floor_z = -1.5f;  // metres, LiDAR frame; from the shown cloud
  gfx::LineRenderer scene_lines;
  gfx::TriangleRenderer scene_quads;
  std::map<std::string, std::unique_ptr<gfx::ImageTexture>> thumbnails;
};

}  // namespace calibench::ui
