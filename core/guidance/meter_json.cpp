#include "core/guidance/meter_json.h"

namespace calibench {

nlohmann::json MatrixJson(const Mat4& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::json VecJson(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json MeterJson(int pairs_used, const CaptureGoal& goal, const std::string& transform_name,
                         const std::optional<Pose>& transform,
                         const std::optional<CaptureState>& state,
                         const std::string& no_solution_note) {
  nlohmann::json out;
  out["pairs_used"] = pairs_used;
  out["goal"] = {{"t_mm", goal.translation_mm}, {"r_deg", goal.rotation_deg}};
  const bool solved = transform && state;
  out[transform_name] = solved ? MatrixJson(transform->matrix()) : nlohmann::json();
  out["sigma_t_mm"] = solved ? VecJson(state->sigma_t_mm) : nlohmann::json();
  out["sigma_r_deg"] = solved ? VecJson(state->sigma_r_deg) : nlohmann::json();
  out["done"] = solved && state->done;
  out["goal_met"] = solved && state->goal_met;
  out["trustworthy"] = solved && state->trustworthy;
  out["trust_note"] = solved ? state->trust_note : no_solution_note;
  out["weakest"] = solved ? state->weakest : "";
  return out;
}

}  // namespace calibench
