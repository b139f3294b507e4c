// Reading what `calibench watch --json-lines` printed: its lines as JSON (lines that are not
// JSON, such as a library's warning on stderr, are skipped) and a pose given as 4 rows.
#pragma once

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/types.h"

namespace calibench::test {

inline std::vector<nlohmann::json> ReadJsonLines(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] == '{') lines.push_back(nlohmann::json::parse(line));
  return lines;
}

inline Pose PoseFromRows(const nlohmann::json& rows) {
  Mat4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  return Pose(m);
}

}  // namespace calibench::test
