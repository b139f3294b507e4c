// Internal to core/report: the pieces every report's HTML is made of (escaping, numbers, the
// transform's cards, the provenance table, the views, the template filled with the data the plots
// read), shared by the LiDAR-camera, rig and LRF reports.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/report/report_html.h"
#include "core/results/export.h"

namespace calibench::report_html {

std::string Escape(const std::string& text);
std::string Base64(const std::string& bytes);
std::string Num(double value, int digits);
std::string Opt(const std::optional<double>& value, int digits);  // "–" when absent
// The file's bytes; throws IoError naming the file and `what` it is.
std::string ReadText(const std::filesystem::path& path, const std::string& what);

// One direction of the transform: its name, its meaning in words, the 4x4 matrix, the
// translation and the quaternion.
std::string DirectionCard(const std::string& name, const std::string& meaning, const Pose& pose);
// Both directions of cam_from_<source> as cards (`source` as in the result's keys: "lidar" or
// "lrf"; `sensor` as a person reads it: "LiDAR" or "LRF").
std::string DirectionCards(const std::string& source, const std::string& sensor,
                           const Pose& cam_from_source);
// σ per camera axis: translation in mm, rotation in degrees.
std::string SigmaTable(const Vec3& sigma_t_mm, const Vec3& sigma_r_deg);
// The URDF joint and the ROS 2 static transform of cam_from_<source> under `frames`.
std::string ExportSnippets(const Pose& cam_from_source, const ExportFrames& frames);
// The provenance table at the top (and the provenance's notes under it).
std::string HeaderFacts(const ReportProvenance& provenance, const std::string& pairs,
                        const std::string& options);
// The views, each a data: URI; "" without any. Ids start with `prefix`.
std::string FiguresSection(const std::vector<ReportFigure>& figures, const std::string& prefix);
// The whole page: the template with its style, Chart.js, `data` (REPORT, what report.js plots),
// the script and `body`.
std::string FillReport(const std::string& title, const std::string& body, nlohmann::json data,
                       const ReportAssets& assets);

}  // namespace calibench::report_html
