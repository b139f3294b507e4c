// Lines both solver panels show about a solution: a pose as its 3x4 matrix, the standard
// deviations, whether the data constrains every direction.
#pragma once

#include <string>

#include "core/base/types.h"
#include "core/estimation/uncertainty.h"

namespace calibench::ui {

// `name` then `words` greyed in brackets, then the rotation | translation rows (metres).
void PoseReadout(const char* name, const char* words, const Pose& pose);
// The standard deviations along the camera axes: translation in mm, rotation in degrees.
void StdReadout(const Vec3& translation_mm, const Vec3& rotation_deg);
// "well constrained (<details>)" in green; else `advice` in orange and each weak direction.
void ObservabilityReadout(const ObservabilityReport& report, const std::string& details,
                          const char* advice);

}  // namespace calibench::ui
