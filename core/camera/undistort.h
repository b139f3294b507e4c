// A distortion-free pinhole view of a camera image, for display: straight board edges and
// straight LiDAR rings on walls make misalignment easy to judge.
#pragma once

#include <vector>

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

// The same, with the per-pixel map through the lens computed once for a camera and applied to
// many of its images (the map costs more than the remapping: one lens projection per pixel).
// Apply is const and safe from several threads.
class Undistorter {
 public:
  // For images of width x height (default: the camera's). scale (0, 1]: the view this much
  // smaller than the image (its pinhole scaled with it), for a picture shown small.
  explicit Undistorter(const CameraModel& camera, int width = 0, int height = 0,
                       double scale = 1.0);
  const CameraModel& pinhole() const { return pinhole_; }
  // image must be of the size given.
  UndistortedView Apply(const ImageU8& image) const;

 private:
  CameraModel pinhole_;
  int width_ = 0, height_ = 0;  // the source images'

  std::vector<float> map_x_, map_y_;  // source pixel per target pixel (row-major); -1: none
};

}  // namespace calibench
