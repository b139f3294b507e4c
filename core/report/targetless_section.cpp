#include "core/report/targetless_section.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/io/json_io.h"

namespace calibench {
namespace {

std::string EscapeHtml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string FixedDigits(double value, int digits) {
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

Vec3 JsonTriple(const nlohmann::json& j, const std::filesystem::path& path, const char* key) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_array() || v.size() != 3)
    throw IoError(path.string() + ": \"" + key + "\" must be 3 numbers");
  return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
}

// The cost along the weakest direction: a polyline in a 360x140 box, the calibration at 0.
std::string ProfileSvg(const TargetlessCheckSection& c) {
  if (c.weakest_offsets.size() < 2 || c.weakest_offsets.size() != c.weakest_costs.size()) return "";
  const auto [lo, hi] = std::minmax_element(c.weakest_costs.begin(), c.weakest_costs.end());
  const double x0 = c.weakest_offsets.front(), x1 = c.weakest_offsets.back();
  const double span = std::max(*hi - *lo, 1e-9);
  std::string points;
  for (size_t i = 0; i < c.weakest_offsets.size(); ++i) {
    const double x = 20 + 320 * (c.weakest_offsets[i] - x0) / (x1 - x0);
    const double y = 120 - 100 * (c.weakest_costs[i] - *lo) / span;
    points += FixedDigits(x, 1) + "," + FixedDigits(y, 1) + " ";
  }
  const double zero_x = 20 + 320 * (0 - x0) / (x1 - x0);
  return "<figure><svg class=\"profile\" viewBox=\"0 0 360 140\" width=\"360\" height=\"140\" "
         "role=\"img\" aria-label=\"cost along the weakest direction\">"
         "<line x1=\"" +
         FixedDigits(zero_x, 1) + "\" y1=\"10\" x2=\"" + FixedDigits(zero_x, 1) +
         "\" y2=\"125\" stroke=\"#999\" stroke-dasharray=\"3 3\"/>"
         "<polyline fill=\"none\" stroke=\"#2a6\" stroke-width=\"2\" points=\"" +
         points + "\"/><text x=\"20\" y=\"138\" font-size=\"10\">" + FixedDigits(x0, 1) +
         " tol.</text><text x=\"300\" y=\"138\" font-size=\"10\">+" + FixedDigits(x1, 1) +
         " tol.</text></svg><figcaption>The scene's robust cost along its least constrained "
         "direction about the estimate, in units of the tolerance (dashed: the estimate). A flat "
         "curve is a direction the scene cannot tell.</figcaption></figure>";
}

}  // namespace

TargetlessCheckSection LoadTargetlessCheck(const std::filesystem::path& path) {
  const nlohmann::json j = json_io::ReadJson(path);
  if (!j.is_object() || !j.contains("verdict") || !j["verdict"].is_string())
    throw IoError(path.string() +
                  ": not what `calibench check --json` prints (no \"verdict\"); write it with "
                  "calibench check --dataset D --result R --json > " +
                  path.string());
  TargetlessCheckSection c;
  c.source = path.string();
  try {
    c.verdict = j["verdict"];
    c.why = j.value("why", "");
    c.frames_used = j.value("frames_used", 0);
    c.frames_given = j.value("frames_given", 0);
    for (const auto& axis : j.value("unconstrained_axes", nlohmann::json::array()))
      c.unconstrained_axes.push_back(axis.get<std::string>());
    c.has_estimate = j.contains("cam_from_lidar") && !j["cam_from_lidar"].is_null();
    if (c.has_estimate) {
      c.change_t_mm = JsonTriple(j, path, "change_t_mm");
      c.change_r_deg = JsonTriple(j, path, "change_r_deg");
      c.sigma_t_mm = JsonTriple(j, path, "sigma_t_mm");
      c.sigma_r_deg = JsonTriple(j, path, "sigma_r_deg");
      c.change_sigmas = j.value("change_sigmas", 0.0);
    }
    if (j.contains("weakest_profile") && j["weakest_profile"].is_object()) {
      c.weakest_offsets = j["weakest_profile"].value("offsets_tolerance", std::vector<double>{});
      c.weakest_costs = j["weakest_profile"].value("costs", std::vector<double>{});
    }
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path.string() + ": the check's JSON is damaged: " + e.what());
  }
  return c;
}

std::string TargetlessCheckHtml(const TargetlessCheckSection& c) {
  const std::string kind = c.verdict == "consistent"      ? "good"
                           : c.verdict == "miscalibrated" ? "bad"
                                                          : "warn";
  std::string html =
      "<section id=\"targetless-check\"><h2>Targetless check</h2><p>The calibration judged "
      "without a target, from the edges the LiDAR and the camera both see (<code>calibench "
      "check</code>; " +
      EscapeHtml(c.source) + "; " + std::to_string(c.frames_used) + " of " +
      std::to_string(c.frames_given) + " frames used).</p><p class=\"verdict " + kind + "\">" +
      EscapeHtml(c.verdict) + ": " + EscapeHtml(c.why) + "</p>";
  if (c.has_estimate) {
    html += "<table><tr><th></th><th>x (right)</th><th>y (down)</th><th>z (forward)</th></tr>";
    auto row = [&](const char* name, const Vec3& v, int digits) {
      html += std::string("<tr><td>") + name + "</td><td>" + FixedDigits(v.x(), digits) +
              "</td><td>" + FixedDigits(v.y(), digits) + "</td><td>" + FixedDigits(v.z(), digits) +
              "</td></tr>";
    };
    row("change, translation [mm]", c.change_t_mm, 1);
    row("σ, translation [mm]", c.sigma_t_mm, 1);
    row("change, rotation [deg]", c.change_r_deg, 3);
    row("σ, rotation [deg]", c.sigma_r_deg, 3);
    html += "</table><p>The change is the scene's estimate minus the calibration on camera axes, " +
            FixedDigits(c.change_sigmas, 1) + " σ over the axes the scene constrains.</p>";
  }
  if (!c.unconstrained_axes.empty()) {
    html += "<p>This scene cannot tell: ";
    for (size_t i = 0; i < c.unconstrained_axes.size(); ++i)
      html += (i ? ", " : "") + EscapeHtml(c.unconstrained_axes[i]);
    html += ".</p>";
  }
  return html + ProfileSvg(c) + "</section>";
}

}  // namespace calibench
