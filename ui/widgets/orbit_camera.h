// The orbit camera of the 3D views: the eye on a sphere about a target, looking at it. A left
// drag orbits (0.01 rad a pixel, pitch within +-1.5 rad), the wheel zooms (x0.85 a notch).
// T is the scalar the owner keeps the angles in (the LiDAR-camera workbench keeps them, in
// double, in its session's ViewState; the LRF workbench in float).
#pragma once

#include <Eigen/Core>

#include "ui/gfx/renderers.h"

namespace calibench::ui {

// The frame the 3D view draws in: the LiDAR frame (z up) or a camera frame (y down).
enum class WorldUp { kZUp, kYDown };

template <typename T>
struct OrbitCamera {
  T yaw_rad = 0;    // about the up axis (kZUp: from +x towards +y; kYDown: from +z towards +x)
  T pitch_rad = 0;  // > 0 looks down on the target
  T distance = 1;   // what the wheel scales: metres, or a multiple of the scene's size

  // The unit view direction in the frame's axes.
  Eigen::Vector3f Forward(WorldUp up) const;
  // Perspective (0.9 rad vertical field of view, near plane 0.05 m, far plane far_m) times the
  // look-at from `eye_distance_m` before `target`; aspect = width / height.
  gfx::Matrix4f ViewProjection(const Eigen::Vector3f& target, float eye_distance_m, float aspect,
                               float far_m, WorldUp up) const;
  // A left drag and the wheel over the hovered view. drag_turns_right: dragging to the right
  // increases the yaw (else decreases it). The distance stays within [min_distance,
  // max_distance].
  void HandleMouse(bool drag_turns_right, T min_distance, T max_distance);
};

}  // namespace calibench::ui
