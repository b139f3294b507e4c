// The text pieces every export writer shares (core/results/export.cpp, export_rig.cpp): numbers
// with 17 significant digits, the header saying what the file holds, a pose as xyz +
// quaternion + roll-pitch-yaw text, 4x4 rows. Internal to core/results.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "core/results/export.h"

namespace calibench::export_text {

std::string Number(double value);  // %.17g, no "-0"
std::string Numbers(std::initializer_list<double> values, const char* separator);
std::string CameraFrameWords(CameraFrame frame);
// The header every file carries, one line per entry, for the format's comment syntax.
std::vector<std::string> HeaderLines(const ExportFrames& frames, const std::string& source);
std::string Commented(const std::vector<std::string>& lines, const std::string& prefix);

struct TransformText {
  std::string x, y, z, qx, qy, qz, qw, roll, pitch, yaw;
};
TransformText TextOf(const Pose& parent_from_child);
std::string JointName(const ExportFrames& frames);          // "<parent>_to_<child>"
std::string MatrixRows(const Mat4& m, const char* indent);  // "- [a, b, c, d]" per row

}  // namespace calibench::export_text
