// ReadExportedTransform (core/results/export.h): every export format read back, by extension
// and content -- for round-trip tests and for `evaluate --reference` with a calibration made
// elsewhere and exported the same way.
#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <fstream>
#include <map>
#include <sstream>

#include "core/results/export.h"
#include "core/results/result_file.h"

namespace calibench {

namespace {

[[noreturn]] void Fail(const std::filesystem::path& path, const std::string& problem) {
  throw IoError("calibration file '" + path.string() + "': " + problem);
}

std::string ReadText(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) Fail(path, "no such file");
  if (std::filesystem::file_size(path, error) > (16u << 20)) Fail(path, "larger than 16 MiB");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

double ParseNumber(const std::filesystem::path& path, std::string_view token) {
  double value = 0.0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  if (result.ec != std::errc() || result.ptr != token.data() + token.size())
    Fail(path, "'" + std::string(token) + "' is not a number");
  return value;
}

std::vector<double> ParseNumbers(const std::filesystem::path& path, const std::string& text) {
  std::vector<double> values;
  std::istringstream words(text);
  for (std::string word; words >> word;) values.push_back(ParseNumber(path, word));
  return values;
}

Pose PoseFromXyzRpy(const Vec3& xyz, const Vec3& rpy) {
  Pose pose = Pose::Identity();
  pose.linear() = RotationFromRollPitchYaw(rpy.x(), rpy.y(), rpy.z());
  pose.translation() = xyz;
  return pose;
}

Pose PoseFromXyzQuaternion(const std::vector<double>& v) {  // x y z qx qy qz qw
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Quaterniond(v[6], v[3], v[4], v[5]).normalized().toRotationMatrix();
  pose.translation() = Vec3(v[0], v[1], v[2]);
  return pose;
}

tinyxml2::XMLElement* XmlRoot(const std::filesystem::path& path, const std::string& text,
                              tinyxml2::XMLDocument* document) {
  if (document->Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    Fail(path, std::string("not valid XML: ") + document->ErrorStr());
  return document->RootElement();
}

ImportedTransform ReadUrdf(const std::filesystem::path& path, const tinyxml2::XMLElement& robot) {
  const tinyxml2::XMLElement* joint = robot.FirstChildElement("joint");
  if (joint == nullptr) Fail(path, "the URDF has no <joint>");
  const auto* parent = joint->FirstChildElement("parent");
  const auto* child = joint->FirstChildElement("child");
  const auto* origin = joint->FirstChildElement("origin");
  if (!parent || !child || !parent->Attribute("link") || !child->Attribute("link"))
    Fail(path, "the joint has no <parent link=...> or <child link=...>");
  const std::vector<double> xyz =
      ParseNumbers(path, origin && origin->Attribute("xyz") ? origin->Attribute("xyz") : "0 0 0");
  const std::vector<double> rpy =
      ParseNumbers(path, origin && origin->Attribute("rpy") ? origin->Attribute("rpy") : "0 0 0");
  if (xyz.size() != 3 || rpy.size() != 3) Fail(path, "<origin> needs xyz and rpy of 3 numbers");
  return {ExportFormat::kUrdf, parent->Attribute("link"), child->Attribute("link"),
          PoseFromXyzRpy(Vec3(xyz[0], xyz[1], xyz[2]), Vec3(rpy[0], rpy[1], rpy[2]))};
}

// static_transform_publisher's arguments: x y z qx qy qz qw parent child, or x y z yaw pitch
// roll parent child.
ImportedTransform FromTfArguments(const std::filesystem::path& path,
                                  const std::vector<std::string>& words, ExportFormat format) {
  // The numbers come first (7 with a quaternion, 6 with yaw pitch roll), then the two frames and,
  // in ROS 1, an optional period in ms.
  size_t numbers = 0;
  while (numbers < words.size() && numbers < 7) {
    double ignored = 0.0;
    const std::string& w = words[numbers];
    const auto parsed = std::from_chars(w.data(), w.data() + w.size(), ignored);
    if (parsed.ec != std::errc() || parsed.ptr != w.data() + w.size()) break;
    ++numbers;
  }
  if ((numbers != 6 && numbers != 7) || words.size() < numbers + 2)
    Fail(path,
         "static_transform_publisher takes x y z qx qy qz qw (or yaw pitch roll) "
         "frame_id child_frame_id");
  std::vector<double> v;
  for (size_t i = 0; i < numbers; ++i) v.push_back(ParseNumber(path, words[i]));
  ImportedTransform imported{format, words[numbers], words[numbers + 1], Pose::Identity()};
  imported.parent_from_child = numbers == 7
                                   ? PoseFromXyzQuaternion(v)
                                   : PoseFromXyzRpy(Vec3(v[0], v[1], v[2]), Vec3(v[5], v[4], v[3]));
  return imported;
}

ImportedTransform ReadRos1Launch(const std::filesystem::path& path,
                                 const tinyxml2::XMLElement& launch) {
  for (const auto* node = launch.FirstChildElement("node"); node;
       node = node->NextSiblingElement("node")) {
    const char* type = node->Attribute("type");
    if (!type || std::string_view(type) != "static_transform_publisher" || !node->Attribute("args"))
      continue;
    std::istringstream words(node->Attribute("args"));
    std::vector<std::string> args;
    for (std::string word; words >> word;) args.push_back(word);
    return FromTfArguments(path, args, ExportFormat::kRos1Tf);
  }
  Fail(path, "the launch file has no static_transform_publisher node with args");
}

// A ROS 2 launch file: the quoted strings of the static_transform_publisher's arguments list.
ImportedTransform ReadRos2Launch(const std::filesystem::path& path, const std::string& text) {
  const size_t start = text.find("arguments=[");
  const size_t end = start == std::string::npos ? start : text.find(']', start);
  if (end == std::string::npos) Fail(path, "no arguments=[...] of a static_transform_publisher");
  // The quoted strings of the list, in order ("..." or '...').
  std::vector<std::string> words;
  for (size_t i = start; i < end; ++i) {
    if (text[i] != '"' && text[i] != '\'') continue;
    const size_t close = text.find(text[i], i + 1);
    if (close == std::string::npos || close > end) break;
    words.push_back(text.substr(i + 1, close - i - 1));
    i = close;
  }
  if (words.empty() || words[0].rfind("--", 0) != 0)
    return FromTfArguments(path, words, ExportFormat::kRos2Tf);  // the old positional form
  std::map<std::string, std::string> flags;
  for (size_t i = 0; i + 1 < words.size(); i += 2) flags[words[i]] = words[i + 1];
  std::vector<double> v;
  for (const char* flag : {"--x", "--y", "--z", "--qx", "--qy", "--qz", "--qw"})
    v.push_back(flags.count(flag) ? ParseNumber(path, flags[flag]) : (flag[3] == 'w' ? 1.0 : 0.0));
  if (!flags.count("--frame-id") || !flags.count("--child-frame-id"))
    Fail(path, "the arguments need --frame-id and --child-frame-id");
  Pose pose = PoseFromXyzQuaternion(v);
  if (flags.count("--roll") || flags.count("--pitch") || flags.count("--yaw")) {
    auto angle = [&](const char* flag) {
      return flags.count(flag) ? ParseNumber(path, flags[flag]) : 0.0;
    };
    pose.linear() = RotationFromRollPitchYaw(angle("--roll"), angle("--pitch"), angle("--yaw"));
  }
  return {ExportFormat::kRos2Tf, flags["--frame-id"], flags["--child-frame-id"], pose};
}

double YamlNumber(const std::filesystem::path& path, const YAML::Node& node, const char* what) {
  if (!node || !node.IsScalar())
    Fail(path, std::string("'") + what + "' is missing or not a number");
  return ParseNumber(path, node.Scalar());
}

Mat4 YamlMatrix(const std::filesystem::path& path, const YAML::Node& node, const char* what) {
  std::vector<double> values;
  const YAML::Node data = node.IsMap() ? node["data"] : node;
  if (!data || !data.IsSequence()) Fail(path, std::string("'") + what + "' is not a matrix");
  for (const YAML::Node& item : data) {
    if (item.IsSequence()) {
      for (const YAML::Node& value : item) values.push_back(YamlNumber(path, value, what));
    } else {
      values.push_back(YamlNumber(path, item, what));
    }
  }
  if (values.size() != 16) Fail(path, std::string("'") + what + "' needs 16 numbers (4x4)");
  Mat4 m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = values[i];
  return m;
}

Pose RigidPose(const std::filesystem::path& path, const Mat4& m) {
  const Mat3 r = m.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Mat3::Identity()).norm() > 1e-6 ||
      std::abs(r.determinant() - 1) > 1e-6 || m.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
    Fail(path, "the matrix is not a rigid transform (rotation | translation; 0 0 0 1)");
  Pose pose = Pose::Identity();
  pose.matrix() = m;
  return pose;
}

std::string YamlText(const YAML::Node& node) {
  return node && node.IsScalar() ? node.Scalar() : "";
}

ImportedTransform ReadYaml(const std::filesystem::path& path, std::string text) {
  if (text.rfind("%YAML:1.", 0) == 0) text = "%YAML 1.2" + text.substr(text.find('\n'));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    Fail(path, "not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) Fail(path, "not a calibration (a YAML map was expected)");
  if (root["parent_from_child"])
    return {ExportFormat::kOpenCvYaml, YamlText(root["parent_frame"]),
            YamlText(root["child_frame"]),
            RigidPose(path, YamlMatrix(path, root["parent_from_child"], "parent_from_child"))};
  if (root["cam0"] && root["cam0"].IsMap()) {
    const YAML::Node cam = root["cam0"];
    for (const char* key : {"T_cam_lidar", "T_lidar_cam"}) {
      if (!cam[key]) continue;
      // Kalibr's T_child_parent: its inverse is the pose of the child in the parent.
      return {ExportFormat::kKalibr, YamlText(cam["parent_frame"]), YamlText(cam["child_frame"]),
              RigidPose(path, YamlMatrix(path, cam[key], key)).inverse()};
    }
    Fail(path, "cam0 has neither T_cam_lidar nor T_lidar_cam");
  }
  // Autoware: parent: child: {x y z roll pitch yaw}.
  for (const auto& parent : root) {
    if (!parent.second.IsMap()) continue;
    for (const auto& child : parent.second) {
      const YAML::Node& v = child.second;
      if (!v.IsMap() || !v["x"] || !v["roll"]) continue;
      return {ExportFormat::kAutoware, parent.first.Scalar(), child.first.Scalar(),
              PoseFromXyzRpy(
                  Vec3(YamlNumber(path, v["x"], "x"), YamlNumber(path, v["y"], "y"),
                       YamlNumber(path, v["z"], "z")),
                  Vec3(YamlNumber(path, v["roll"], "roll"), YamlNumber(path, v["pitch"], "pitch"),
                       YamlNumber(path, v["yaw"], "yaw")))};
    }
  }
  Fail(path,
       "no calibration in it (parent_from_child, cam0 T_cam_lidar, or <parent>: <child>: "
       "x y z roll pitch yaw)");
}

ImportedTransform ReadTxt(const std::filesystem::path& path, const std::string& text) {
  ImportedTransform imported;
  std::string numbers;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const size_t hash = line.find('#');
    // "# parent: <name>  child: <name>", as Calibench writes it.
    std::istringstream comment(hash == std::string::npos ? "" : line.substr(hash + 1));
    std::string parent_key, parent, child_key, child;
    if (comment >> parent_key >> parent >> child_key >> child && parent_key == "parent:" &&
        child_key == "child:") {
      imported.parent = parent;
      imported.child = child;
    }
    numbers += line.substr(0, hash) + " ";
  }
  std::vector<double> v = ParseNumbers(path, numbers);
  if (v.size() == 12) v.insert(v.end(), {0, 0, 0, 1});
  if (v.size() != 16)
    Fail(path,
         "a 4x4 (or 3x4) matrix was expected, found " + std::to_string(v.size()) + " numbers");
  Mat4 m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = v[i];
  imported.format = ExportFormat::kTxt;
  imported.parent_from_child = RigidPose(path, m);
  return imported;
}

}  // namespace

ImportedTransform ReadExportedTransform(const std::filesystem::path& path) {
  const std::string text = ReadText(path);
  const std::string name = path.filename().string();
  const auto ends_with = [&](const char* suffix) { return name.ends_with(suffix); };
  if (ends_with(".json")) {  // a calibench result: cam_from_lidar, parent = LiDAR
    const LoadedResult result = LoadResult(path);
    return {std::nullopt, "lidar", "camera", result.cam_from_source.inverse()};
  }
  if (ends_with(".py")) return ReadRos2Launch(path, text);
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '<') {
    tinyxml2::XMLDocument document;
    const tinyxml2::XMLElement* root = XmlRoot(path, text, &document);
    if (root && std::string_view(root->Name()) == "robot") return ReadUrdf(path, *root);
    if (root && std::string_view(root->Name()) == "launch") return ReadRos1Launch(path, *root);
    Fail(path, "XML that is neither a URDF <robot> nor a ROS 1 <launch> file");
  }
  if (ends_with(".yaml") || ends_with(".yml")) return ReadYaml(path, text);
  return ReadTxt(path, text);
}

}  // namespace calibench
