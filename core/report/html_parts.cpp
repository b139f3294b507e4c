#include "core/report/html_parts.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

namespace calibench::report_html {

using nlohmann::json;

namespace {

// Fills {{name}} placeholders of the template in one pass: inserted text is never scanned again.
std::string FillTemplate(const std::string& tpl, const std::map<std::string, std::string>& values) {
  std::string out;
  size_t at = 0;
  while (true) {
    const size_t open = tpl.find("{{", at);
    const size_t close = open == std::string::npos ? open : tpl.find("}}", open);
    if (close == std::string::npos) break;
    out.append(tpl, at, open - at);
    const auto value = values.find(tpl.substr(open + 2, close - open - 2));
    out += value != values.end() ? value->second : tpl.substr(open, close + 2 - open);
    at = close + 2;
  }
  out.append(tpl, at, std::string::npos);
  return out;
}

std::string MatrixTable(const Pose& pose) {
  std::string html = "<table class=\"matrix\">";
  for (int r = 0; r < 3; ++r) {
    html += "<tr>";
    for (int c = 0; c < 3; ++c) html += "<td>" + Num(pose.linear()(r, c), 6) + "</td>";
    html += "<td class=\"t\">" + Num(pose.translation()(r), 6) + "</td></tr>";
  }
  return html + "<tr><td>0</td><td>0</td><td>0</td><td class=\"t\">1</td></tr></table>";
}

}  // namespace

std::string Escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  static constexpr char kTable[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k)
      v = (v << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kTable[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string Num(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

std::string Opt(const std::optional<double>& value, int digits) {
  return value ? Num(*value, digits) : "&ndash;";
}

std::string ReadText(const std::filesystem::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path.string() + ": cannot read " + what);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string DirectionCard(const std::string& name, const std::string& meaning, const Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  return "<div class=\"card\"><h3><code>" + name + "</code></h3><p class=\"meaning\">" + meaning +
         "</p>" + MatrixTable(pose) + "<p>translation [m]: " + Num(pose.translation().x(), 6) +
         " " + Num(pose.translation().y(), 6) + " " + Num(pose.translation().z(), 6) +
         "<br>quaternion x y z w: " + Num(q.x(), 6) + " " + Num(q.y(), 6) + " " + Num(q.z(), 6) +
         " " + Num(q.w(), 6) + "</p></div>";
}

std::string FiguresSection(const std::vector<ReportFigure>& figures, const std::string& prefix) {
  if (figures.empty()) return "";
  std::string html = "<section id=\"" + prefix + "views\"><h2>Views</h2><div class=\"figures\">";
  for (const ReportFigure& f : figures) {
    html += "<figure" +
            (f.pair_id.empty() ? std::string(" class=\"overview\"")
                               : " data-figure-pair=\"" + Escape(f.pair_id) + "\"") +
            "><img alt=\"" + Escape(f.title) + "\" src=\"data:" + f.mime + ";base64," +
            Base64(f.bytes) + "\"><figcaption>" + Escape(f.title) + "</figcaption></figure>";
  }
  return html + "</div></section>";
}

std::string DirectionCards(const std::string& source, const std::string& sensor,
                           const Pose& cam_from_source) {
  return DirectionCard(
             "cam_from_" + source,
             "maps " + sensor + " points into the camera frame: p_cam = R p_" + source + " + t",
             cam_from_source) +
         DirectionCard(source + "_from_cam",
                       "maps camera points into the " + sensor + " frame: p_" + source +
                           " = R p_cam + t (t is the camera's position in the " + sensor +
                           " frame)",
                       cam_from_source.inverse());
}

std::string SigmaTable(const Vec3& sigma_t_mm, const Vec3& sigma_r_deg) {
  std::string html =
      "<table class=\"sigma\"><tr><th>standard deviation (camera axes)</th><th>x</th>"
      "<th>y</th><th>z</th></tr><tr><td>translation [mm]</td>";
  for (int i = 0; i < 3; ++i) html += "<td>" + Num(sigma_t_mm[i], 2) + "</td>";
  html += "</tr><tr><td>rotation [deg]</td>";
  for (int i = 0; i < 3; ++i) html += "<td>" + Num(sigma_r_deg[i], 3) + "</td>";
  return html + "</tr></table>";
}

std::string ExportSnippets(const Pose& cam_from_source, const ExportFrames& frames) {
  const std::string urdf =
      ExportCalibration(ExportFormat::kUrdf, cam_from_source, frames, "this report").text;
  const std::string ros2 =
      ExportCalibration(ExportFormat::kRos2Tf, cam_from_source, frames, "this report").command;
  const std::string parent =
      frames.lidar == ExportFrames{}.lidar ? "" : " --parent-frame " + frames.lidar;
  return "<h3>Export</h3><p>URDF joint (<code>calibench export --format urdf" + Escape(parent) +
         "</code>):</p><pre class=\"snippet\">" + Escape(urdf) +
         "</pre><p>ROS 2 static transform:</p><pre class=\"snippet\">" + Escape(ros2) + "</pre>";
}

// The provenance table, the notes and the report's own warning, as the header opens.
std::string HeaderFacts(const ReportProvenance& provenance, const std::string& pairs,
                        const std::string& options) {
  std::string html = "<table class=\"provenance\">";
  auto fact = [&](const std::string& name, const std::string& value) {
    if (!value.empty()) html += "<tr><th>" + name + "</th><td>" + Escape(value) + "</td></tr>";
  };
  fact("source", provenance.source);
  fact("result", provenance.result_file);
  fact("pairs", pairs);
  fact("options", options);
  fact("written", provenance.created_utc);
  fact("Calibench", provenance.calibench_version);
  html += "</table>";
  for (const std::string& note : provenance.notes)
    html += "<p class=\"verdict bad\">" + Escape(note) + "</p>";
  return html;
}

std::string FillReport(const std::string& title, const std::string& body, json data,
                       const ReportAssets& assets) {
  std::string text = data.dump();
  for (size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3))
    text.replace(at, 2, "<\\/");  // never close the <script> early
  return FillTemplate(assets.html_template, {{"title", title},
                                             {"style", assets.style},
                                             {"chart_js", assets.chart_js},
                                             {"data", text},
                                             {"script", assets.script},
                                             {"body", body}});
}

}  // namespace calibench::report_html
