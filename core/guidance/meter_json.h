// The JSON of a capture meter shared by `advise --json` for both methods (included by
// core/guidance's .cpp files only: nlohmann-json stays private to the library).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/guidance/stop_rule.h"

namespace calibench {

nlohmann::json MatrixJson(const Mat4& m);  // nested rows
nlohmann::json VecJson(const Vec3& v);

// pairs_used, goal, the transform under `transform_name` (null without a solution), sigma_t_mm,
// sigma_r_deg, done, goal_met, trustworthy, trust_note (`no_solution_note` without a state) and
// weakest.
nlohmann::json MeterJson(int pairs_used, const CaptureGoal& goal, const std::string& transform_name,
                         const std::optional<Pose>& transform,
                         const std::optional<CaptureState>& state,
                         const std::string& no_solution_note);

}  // namespace calibench
