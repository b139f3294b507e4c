#include "ui/state/view_state.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/base/names.h"
#include "core/io/json_fields.h"

namespace calibench::ui {
namespace {

using Json = nlohmann::json;  // sorted members: the text a reread file gives back
using json_io::Fields;

constexpr EnumName<LidarChannel> kChannelNames[] = {{LidarChannel::kIntensity, "intensity"},
                                                    {LidarChannel::kRange, "range"},
                                                    {LidarChannel::kRing, "ring"}};
constexpr EnumName<CameraImageMode> kImageModeNames[] = {
    {CameraImageMode::kRaw, "raw"}, {CameraImageMode::kUndistorted, "undistorted"}};
constexpr EnumName<VisibilityMode> kVisibilityNames[] = {{VisibilityMode::kHpr, "hpr"},
                                                         {VisibilityMode::kZBuffer, "zbuffer"},
                                                         {VisibilityMode::kNone, "none"}};

// JSON has no NaN/inf; a session holding one must still load, so they become strings.
Json Number(double value) {
  if (std::isfinite(value)) return value;
  if (std::isnan(value)) return "nan";
  return value > 0 ? "inf" : "-inf";
}

}  // namespace

std::string LidarChannelName(LidarChannel channel) { return NameIn(kChannelNames, channel); }
std::string CameraImageModeName(CameraImageMode mode) { return NameIn(kImageModeNames, mode); }
std::string VisibilityModeName(VisibilityMode mode) { return NameIn(kVisibilityNames, mode); }

std::string ViewToJson(const ViewState& v) {
  const Json view = {
      {"selected_pair", v.selected_pair},
      {"lidar_channel", LidarChannelName(v.lidar_channel)},
      {"camera_image", CameraImageModeName(v.camera_image)},
      {"visibility", VisibilityModeName(v.visibility)},
      {"hpr_radius_exponent", Number(v.hpr_radius_exponent)},
      {"point_size_px", Number(v.point_size_px)},
      {"point_opacity", Number(v.point_opacity)},
      {"orbit_yaw_rad", Number(v.orbit_yaw_rad)},
      {"orbit_pitch_rad", Number(v.orbit_pitch_rad)},
      {"orbit_distance_m", Number(v.orbit_distance_m)},
      {"orbit_target_m",
       {Number(v.orbit_target[0]), Number(v.orbit_target[1]), Number(v.orbit_target[2])}},
      {"brush_radius_px", Number(v.brush_radius_px)}};
  return view.dump();
}

ViewState ViewFromJson(const std::string& text, const std::filesystem::path& source,
                       const std::vector<std::string>& pair_ids) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    json_io::FailAt(source, "view", std::string("not valid JSON: ") + e.what());
  }
  const Fields f(root, source, "view");
  ViewState v;
  v.selected_pair = pair_ids.empty() ? "" : pair_ids.front();
  if (f.Has("selected_pair")) v.selected_pair = f.String("selected_pair");
  if (!v.selected_pair.empty() &&
      std::find(pair_ids.begin(), pair_ids.end(), v.selected_pair) == pair_ids.end())
    f.Fail("selected_pair", "\"" + v.selected_pair + "\" is not a pair");
  if (f.Has("lidar_channel")) v.lidar_channel = f.Name("lidar_channel", kChannelNames);
  if (f.Has("camera_image")) v.camera_image = f.Name("camera_image", kImageModeNames);
  if (f.Has("visibility")) v.visibility = f.Name("visibility", kVisibilityNames);
  if (f.Has("hpr_radius_exponent")) v.hpr_radius_exponent = f.StoredNumber("hpr_radius_exponent");
  if (f.Has("point_size_px")) v.point_size_px = f.Positive("point_size_px");
  if (f.Has("point_opacity")) v.point_opacity = f.StoredNumber("point_opacity");
  if (!(v.point_opacity >= 0.0 && v.point_opacity <= 1.0))
    f.Fail("point_opacity", "must lie in [0, 1]");
  if (f.Has("orbit_yaw_rad")) v.orbit_yaw_rad = f.StoredNumber("orbit_yaw_rad");
  if (f.Has("orbit_pitch_rad")) v.orbit_pitch_rad = f.StoredNumber("orbit_pitch_rad");
  if (f.Has("orbit_distance_m")) v.orbit_distance_m = f.Positive("orbit_distance_m");
  if (f.Has("orbit_target_m")) {
    const auto& target = f.Array("orbit_target_m", 3);
    for (int i = 0; i < 3; ++i)
      v.orbit_target[i] =
          json_io::NumberAt(target[i], source, f.Path("orbit_target_m"), /*allow_non_finite=*/true);
  }
  if (f.Has("brush_radius_px")) v.brush_radius_px = f.Positive("brush_radius_px");
  return v;
}

ViewState FramedOn(ViewState view, const std::array<double, 3>& center, double radius_m) {
  view.orbit_target = center;
  // Within 0.2 m of the LiDAR's z axis the bearing says nothing: the user's yaw stays.
  if (std::hypot(center[0], center[1]) > 0.2) view.orbit_yaw_rad = std::atan2(center[1], center[0]);
  // The orbit camera's vertical field of view is 0.9 rad (ui/widgets/orbit_camera.h): a sphere
  // of radius r fills it from r / sin(0.45). Within the wheel's range (0.5 to 200 m).
  view.orbit_distance_m = std::clamp(radius_m / std::sin(0.45), 0.5, 200.0);
  return view;
}

}  // namespace calibench::ui
