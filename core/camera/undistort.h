// A distortion-free pinhole view of a camera image, for display: straight board edges and
// straight LiDAR rings on walls make misalignment easy to judge.
#pragma once

#include "core/base/image.h"
#include "core/camera/camera.h"

namespace calibench {

struct UndistortedView {
  CameraModel pinhole;  // no distortion; project points with it to draw on `image`
  ImageU8 image;        // same size as the source
};

// Pinhole rad-tan keeps its K. Kannala-Brandt (fields of view up to 180 degrees, which no pinhole
// image holds) gets a focal length that shows +-60 degrees across the width. Pixels that map
// outside the source are black. Bilinear sampling.
UndistortedView Undistort(const CameraModel& camera, const ImageU8& image);

}  // namespace calibench
