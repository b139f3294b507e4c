// Camera side of a pair: find the board in the image, solve planar PnP through the camera model,
// and express the board plane in the camera frame with its covariance.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/board/board.h"
#include "core/camera/camera.h"
#include "core/geometry/geometry.h"

namespace calibench {

struct BoardDetectionOptions {
  // cornerSubPix refinement after findChessboardCornersSB removes its ~0.06–0.10 px bias at small
  // squares (measured on rendered boards). Half window in pixels; 0 = choose from square size.
  int subpix_half_window_px = 0;
  // OpenCV 4.6 ChArUco corner interpolation is offset by +0.5 px in x and y (OpenCV issue 25539).
  bool correct_charuco_offset = true;
  int min_corners = 6;  // fewer detected corners = failed detection
  // Checkerboards: search on the coarsest pyramid level that shows the board (its shorter side
  // >= 240 px), then refine at full resolution; false = search at full resolution only (about
  // 20x slower on 1920 x 1208 images; the corners agree within 0.001 px).
  bool pyramid_search = true;
  // Smallest ArUco marker perimeter as a fraction of the larger image side. OpenCV's default
  // (0.03, i.e. ~11 px markers on a 1440 px image) drops the markers of small boards at range.
  double min_marker_perimeter_rate = 0.01;
  bool Check(std::string* why) const;
};

struct BoardDetection {
  std::vector<Vec2> pixels;        // detected corner positions (pixels)
  std::vector<Vec3> board_points;  // the same corners in the board frame (metres, z = 0)
  std::vector<int> ids;            // corner ids (index into BoardCornerPoints)
};

// nullopt with *why set when the board is not found (too few corners, no markers, ...).
std::optional<BoardDetection> DetectBoard(const ImageU8& image, const BoardSpec& board,
                                          const BoardDetectionOptions& options, std::string* why);

// The corners of `detection`, found in `from`, followed into `to` by pyramidal Lucas-Kanade
// flow (a board held still, or moved a few pixels): what import uses to check that the board
// stood still around a pair without searching each image again. nullopt with *why when fewer
// than `min_tracked_fraction` of the corners are followed (the board moved too far, left the
// view or was covered).
std::optional<BoardDetection> TrackBoard(const ImageU8& from, const BoardDetection& detection,
                                         const ImageU8& to, double min_tracked_fraction,
                                         std::string* why);

// Whether `board` explains what an image shows. A checkerboard detector finds a 5x4 grid inside
// a 7x5 board as readily as on a 5x4 board, so "found" is not enough to choose between presets.
enum class BoardFit {
  kNotFound,      // the board is not in the image
  kPartOfLarger,  // found, but as part of a larger board: a checkerboard with one more column or
                  // row of corners, a ChArUco marker whose id this board does not have
  kFits,          // found, and nothing of it extends beyond the spec
};
BoardFit FitBoard(const ImageU8& image, const BoardSpec& board);

struct CameraBoardObservation {
  Pose cam_from_board;
  Mat6 pose_covariance = Mat6::Zero();   // of cam_from_board, right perturbation, [rho; phi]
  Plane plane;                           // in the camera frame, oriented towards the camera (d > 0)
  Mat4 plane_covariance = Mat4::Zero();  // of (n, d); rank 3 (n is unit)
  double reprojection_rms_px = 0.0;
  double corner_sigma_px = 0.0;  // estimated from the residuals (floored), used for covariances
  int num_corners = 0;
  // The corners the pose was solved from: what the joint refinement of the intrinsics and the
  // propagation of their covariance pose again under another camera (core/lidar_camera/
  // joint_intrinsics.h).
  BoardDetection corners;
};

struct PnpOptions {
  double min_corner_sigma_px = 0.05;  // floor for the residual-based corner noise estimate
  int max_iterations = 20;            // Gauss-Newton refinement in pixel space
  double max_rms_px = 3.0;            // larger reprojection RMS = failed pose
  bool Check(std::string* why) const;
};

// Planar PnP through the camera model (pinhole or fisheye, on the raw image): initialised with
// IPPE on undistorted bearings, refined by Gauss-Newton on pixel residuals. Covariances follow
// from the refined Jacobian and the corner noise. nullopt with *why on failure.
std::optional<CameraBoardObservation> EstimateBoardPose(const CameraModel& camera,
                                                        const BoardDetection& detection,
                                                        const PnpOptions& options,
                                                        std::string* why);

// The board's plane (z = 0, oriented towards the camera) and its covariance from the observation's
// cam_from_board and pose_covariance: what a pose interpolated between frames (a waved board,
// core/lidar_camera/board_track.h) gives the solver.
void SetBoardPlaneFromPose(CameraBoardObservation* observation);

// Motion blur: OpenCV's estimateChessboardSharpness over a checkerboard's full detection, the
// mean width of the squares' edges in pixels (a sharp print: 1.5-2.5 px); nullopt for ChArUco
// or a partial detection.
std::optional<double> ChessboardEdgeWidthPx(const ImageU8& image, const BoardSpec& board,
                                            const BoardDetection& detection);

}  // namespace calibench
