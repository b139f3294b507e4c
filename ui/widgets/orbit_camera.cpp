#include "ui/widgets/orbit_camera.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace calibench::ui {

template <typename T>
Eigen::Vector3f OrbitCamera<T>::Forward(WorldUp up) const {
  const T horizontal_a = std::cos(pitch_rad) * std::cos(yaw_rad);
  const T horizontal_b = std::cos(pitch_rad) * std::sin(yaw_rad);
  if (up == WorldUp::kZUp)
    return Eigen::Vector3f(static_cast<float>(horizontal_a), static_cast<float>(horizontal_b),
                           static_cast<float>(-std::sin(pitch_rad)));
  return Eigen::Vector3f(static_cast<float>(horizontal_b), static_cast<float>(std::sin(pitch_rad)),
                         static_cast<float>(horizontal_a));
}

template <typename T>
gfx::Matrix4f OrbitCamera<T>::ViewProjection(const Eigen::Vector3f& target, float eye_distance_m,
                                             float aspect, float far_m, WorldUp up) const {
  const Eigen::Vector3f eye = target - eye_distance_m * Forward(up);
  const Eigen::Vector3f up_axis =
      up == WorldUp::kZUp ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f(-Eigen::Vector3f::UnitY());
  return gfx::Perspective(0.9f, aspect, 0.05f, far_m) * gfx::LookAt(eye, target, up_axis);
}

template <typename T>
void OrbitCamera<T>::HandleMouse(bool drag_turns_right, T min_distance, T max_distance) {
  const ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
    const T turn = io.MouseDelta.x * static_cast<T>(0.01);
    yaw_rad = drag_turns_right ? yaw_rad + turn : yaw_rad - turn;
    pitch_rad = std::clamp(pitch_rad + io.MouseDelta.y * static_cast<T>(0.01), static_cast<T>(-1.5),
                           static_cast<T>(1.5));
  }
  if (io.MouseWheel != 0)
    distance = std::clamp(distance * std::pow(static_cast<T>(0.85), static_cast<T>(io.MouseWheel)),
                          min_distance, max_distance);
}

template struct OrbitCamera<float>;
template struct OrbitCamera<double>;

}  // namespace calibench::ui
