// What the LiDAR–camera workbench's views showed: the selected pair, colour and visibility modes,
// point style, the 3D view's orbit and the brush size. The session file carries it as its "view"
// object, which core keeps as text it neither reads nor checks (Session::view_json): view state
// is the workbench's, not the pipeline's.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/lidar/colormap.h"

namespace calibench::ui {

enum class CameraImageMode { kRaw, kUndistorted };
// How LiDAR points hidden from the camera are removed in the camera view.
enum class VisibilityMode { kHpr, kZBuffer, kNone };

// Angles radians, distances metres, sizes pixels.
struct ViewState {
  std::string selected_pair;  // pair id; empty = none selected
  LidarChannel lidar_channel = LidarChannel::kIntensity;
  CameraImageMode camera_image = CameraImageMode::kUndistorted;
  VisibilityMode visibility = VisibilityMode::kHpr;
  double hpr_radius_exponent = 2.5;  // Katz R = max_dist * 10^x; HprOptions' default
  double point_size_px = 2.0;        // rendered point diameter, pixels
  double point_opacity = 1.0;        // [0, 1]
  // 3D view: orbit camera about `orbit_target` (LiDAR frame, metres).
  double orbit_yaw_rad = 0.0;     // about the LiDAR z axis, 0 = looking along +x
  double orbit_pitch_rad = 0.35;  // elevation above the xy plane (about 20 degrees)
  double orbit_distance_m = 5.0;  // close enough to see the boards and both sensor frames
  std::array<double, 3> orbit_target = {1.5, 0.0, 0.0};  // in front of the LiDAR
  double brush_radius_px = 6.0;                          // circle brush on the LiDAR image, pixels

  bool operator==(const ViewState&) const = default;
};

// "intensity" / "range" / "ring", "raw" / "undistorted", "hpr" / "zbuffer" / "none".
std::string LidarChannelName(LidarChannel channel);
std::string CameraImageModeName(CameraImageMode mode);
std::string VisibilityModeName(VisibilityMode mode);

// The view as the session file's "view" object (JSON text). Doubles round-trip exactly;
// non-finite ones are the strings "nan", "inf", "-inf", as everywhere in a session.
std::string ViewToJson(const ViewState& view);
// The "view" object of the session `source` (named in errors) over the pairs `pair_ids`. Fields
// it lacks keep their defaults, and without "selected_pair" the first pair is selected (a new
// session's view is empty). Throws IoError naming the file and the field ("view.point_opacity")
// for a malformed object, a mode it does not know, or a selected pair that is not a pair.
ViewState ViewFromJson(const std::string& text, const std::filesystem::path& source,
                       const std::vector<std::string>& pair_ids);

// The 3D view's orbit turned onto `center` (LiDAR frame, metres): the target there, the eye on
// the LiDAR's side of it (yaw along the LiDAR-to-centre bearing, whatever way the LiDAR's axes
// point; kept when the centre lies above the LiDAR), far enough that a sphere of `radius_m` about
// it fits the view's height. Pitch and everything else stay the user's.
ViewState FramedOn(ViewState view, const std::array<double, 3>& center, double radius_m);

}  // namespace calibench::ui
