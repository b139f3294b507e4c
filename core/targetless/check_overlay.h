// The check drawn on a camera image (docs/targetless.md "Views"): the image's edges dimmed, and
// the LiDAR's edges projected under the calibration checked (red) and under the targetless
// estimate (green), for `render --view check`, the report and the workbench's check panel.
#pragma once

#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/targetless/lidar_edges.h"

namespace calibench {

struct OverlayPose {
  Pose cam_from_lidar = Pose::Identity();
  std::uint8_t b = 0, g = 0, r = 255;  // BGR colour of its points
};

// The image (grey, darkened so that coloured points stand out) with every LiDAR edge of the frame
// drawn at each pose, the first pose underneath; `caption` lines, when given, on a dark band at
// the top.
ImageU8 DrawEdgeOverlay(const ImageU8& image, const std::vector<SceneEdgePoint>& lidar_edges,
                        const CameraModel& camera, const std::vector<OverlayPose>& poses,
                        const std::vector<std::string>& caption = {});

}  // namespace calibench
