// The report's targetless-check section (docs/targetless.md "Output"): what `calibench check
// --json` said about the calibration, read back from that JSON, and drawn as a section of the
// HTML report — the verdict, the change and σ per camera axis, the axes the scene cannot tell,
// and the cost along the weakest direction as an inline SVG.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench {

struct TargetlessCheckSection {
  std::string source;  // the check's JSON file
  std::string verdict, why;
  int frames_used = 0, frames_given = 0;
  bool has_estimate = false;
  Vec3 change_t_mm = Vec3::Zero(), change_r_deg = Vec3::Zero();
  Vec3 sigma_t_mm = Vec3::Zero(), sigma_r_deg = Vec3::Zero();
  double change_sigmas = 0.0;
  std::vector<std::string> unconstrained_axes;
  std::vector<double> weakest_offsets, weakest_costs;  // tolerances, robust cost
};

// Reads what `calibench check --json` printed. Throws IoError naming the file when it is not
// that object.
TargetlessCheckSection LoadTargetlessCheck(const std::filesystem::path& path);

// The section's HTML (<section id="targetless-check">...</section>).
std::string TargetlessCheckHtml(const TargetlessCheckSection& check);

}  // namespace calibench
