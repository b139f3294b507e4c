// Camera intrinsics from board images (`calibench intrinsics`, `calibrate --estimate-intrinsics`):
// our board detection (checkerboards, ChArUco, partial ChArUco views), then OpenCV's own
// calibrateCamera / fisheye::calibrate, with bad images rejected and the camera refitted; the
// uncertainty of every parameter, the per-image error, and the coverage of the image with the
// stop rule of OpenCV's interactive calibration, in words.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/target/board_camera.h"

namespace calibench {

struct IntrinsicsOptions {
  CameraModelType model = CameraModelType::kPinholeRadTan;  // or kKannalaBrandt
  // pinhole-radtan: k1 k2 p1 p2 k3 (5); false keeps k3 at 0 (ROS camera_calibration's default
  // for ordinary lenses, and what few images can fix).
  bool estimate_k3 = true;
  // An image whose corner RMS exceeds this many times the median image's (and 1 px) is dropped
  // and the camera refitted, at most max_rounds times: a misdetected board or a motion-blurred
  // frame must not bend the lens.
  double reject_factor = 3.0;
  int max_rounds = 3;
  int min_images = 3;   // fewer usable images = no calibration
  int min_corners = 6;  // per image
  // The stop rule of OpenCV's interactive calibration: 1.96 σ / value below this for fx, fy, cx
  // and cy, and the RMS reprojection error below max_rms_px.
  double max_relative_ci = 0.05;
  double max_rms_px = 0.5;
  // Coverage: corners counted over a grid of cells on the image; the outer ring of cells is the
  // border where the distortion lives.
  int grid_columns = 8;
  int grid_rows = 6;

  bool Check(std::string* why) const;
};

// One image's board corners: pixels and the matching board points (BoardDetection).
struct IntrinsicsView {
  std::string name;  // the image file or pair id, for messages
  BoardDetection detection;
};

struct IntrinsicsImage {
  std::string name;
  int corners = 0;
  double rms_px = 0.0;  // at the final camera (also for rejected images, posed alone)
  bool used = false;
  std::string reason;  // why it was not used
};

struct IntrinsicsCoverage {
  int columns = 0, rows = 0;
  std::vector<int> counts;      // corners per cell, row-major
  double cells_covered = 0.0;   // fraction of cells with a corner
  double border_covered = 0.0;  // fraction of the outer ring's cells with a corner
  // Where corners are missing, in words ("right border", "top-left corner"); empty = none.
  std::vector<std::string> missing;
};

struct IntrinsicsResult {
  CameraModel camera;
  double rms_px = 0.0;                       // over the used images' corners
  std::vector<std::string> parameter_names;  // fx fy cx cy, then the distortion's
  std::vector<double> parameters;
  std::vector<double> sigmas;           // standard deviation per parameter (same order)
  std::vector<IntrinsicsImage> images;  // in the input's order
  IntrinsicsCoverage coverage;
  bool good = false;    // the stop rule holds and the border is covered
  std::string verdict;  // "good" or what to add, in words
};

// Calibrates the camera of `width` x `height` pixels from the views. Throws std::invalid_argument
// when fewer than options.min_images views are usable, naming how many and why.
IntrinsicsResult CalibrateIntrinsics(const std::vector<IntrinsicsView>& views, int width,
                                     int height, const IntrinsicsOptions& options);

// The verdict's coverage part for these corners (also what guidance asks of the next pose).
IntrinsicsCoverage MeasureCoverage(const std::vector<IntrinsicsView>& views, int width, int height,
                                   const IntrinsicsOptions& options);

// The cells of `coverage` without a corner, as pixel boxes of a width x height image (what the
// next pose should put corners in, core/guidance).
std::vector<Eigen::AlignedBox2d> EmptyCells(const IntrinsicsCoverage& coverage, int width,
                                            int height);

// An image file to calibrate from, by name (the pair id or the file's name).
struct IntrinsicsImageFile {
  std::string name;
  std::filesystem::path path;
};

// Reads the images and detects the board in each (in parallel with `threads`): the views with a
// board, and for the others an IntrinsicsImage saying why (no board, unreadable). Sets *width x
// *height from the images; throws IoError naming the file whose size differs from the first's.
std::vector<IntrinsicsView> DetectIntrinsicsViews(const std::vector<IntrinsicsImageFile>& files,
                                                  const BoardSpec& board, int threads, int* width,
                                                  int* height,
                                                  std::vector<IntrinsicsImage>* skipped,
                                                  const BoardDetectionOptions& detection = {});

// A terminal summary: the camera, RMS, σ per parameter, per-image errors, coverage, the verdict.
std::string FormatIntrinsics(const IntrinsicsResult& result);

}  // namespace calibench
