// LoadCameraFile (core/io/camera_file.h): intrinsics from OpenCV FileStorage, ROS
// camera_calibration / CameraInfo YAML and Kalibr camchain files. Every file becomes one
// YAML::Node tree (yaml-cpp for all YAML, OpenCV's %YAML:1.0 files included: it ignores the
// unknown directive and keeps the !!opencv-matrix tags; tinyxml2 for XML), then one
// interpreter picks the format by its keys. Both parsers recurse, so the nesting of the text is
// measured before either sees it.
#include "core/io/camera_file.h"

#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/types.h"
#include "core/io/camera_file_internal.h"

namespace calibench {
namespace {

using camera_file::CheckXmlNesting;
using camera_file::CheckYamlText;
using camera_file::ParseYaml;
using camera_file::Problem;
using camera_file::Quote;
using camera_file::ReadOpenCvXml;
using camera_file::ReadText;

// " (line N)" for a node read from YAML text; nothing for nodes built from XML.
std::string LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? "" : " (line " + std::to_string(mark.line + 1) + ")";
}

// How a value that was not what a field needs looks, for the message.
std::string Shown(const YAML::Node& node) {
  if (node.IsScalar()) return Quote(node.Scalar());
  return node.IsSequence() ? "a list" : node.IsMap() ? "a map" : "nothing";
}

// The value under `key` in a map; nullopt when absent. yaml-cpp keeps both entries of a key
// given twice, which no camera file means: an error.
std::optional<YAML::Node> Find(const YAML::Node& map, const std::string& key) {
  std::optional<YAML::Node> found;
  if (!map.IsMap()) return found;
  for (const auto& entry : map) {
    if (!entry.first.IsScalar() || entry.first.Scalar() != key) continue;
    if (found) throw Problem(Quote(key) + " is given twice" + LineOf(entry.first));
    found.emplace(entry.second);  // emplace: assigning a YAML::Node would overwrite its target
  }
  return found;
}

// A scalar read as a number: decimal or exponent notation, an optional sign, .inf / .nan;
// nullopt for anything else ("1.0abc", "0x10", empty text, lists).
std::optional<double> AsNumber(const YAML::Node& node) {
  if (!node.IsScalar() || node.Scalar().empty()) return std::nullopt;
  const std::string& text = node.Scalar();
  const bool negative = text[0] == '-';
  const std::string body = text[0] == '-' || text[0] == '+' ? text.substr(1) : text;
  if (body.empty() || body[0] == '-' || body[0] == '+') return std::nullopt;
  double value = 0;
  if (body == ".inf" || body == ".Inf" || body == ".INF") {
    value = std::numeric_limits<double>::infinity();
  } else if (body == ".nan" || body == ".NaN" || body == ".NAN") {
    value = std::numeric_limits<double>::quiet_NaN();
  } else {
    const char* end = body.data() + body.size();
    const auto [ptr, error] = std::from_chars(body.data(), end, value);
    if (error != std::errc() || ptr != end) return std::nullopt;
  }
  return negative ? -value : value;
}

int WholeNumber(const YAML::Node& node, const std::string& what) {
  const std::optional<double> value = AsNumber(node);
  if (!value || !(*value >= 0 && *value <= 1e6) || std::floor(*value) != *value) {
    throw Problem(what + " must be a whole number, got " + Shown(node) + LineOf(node));
  }
  return static_cast<int>(*value);
}

std::vector<double> Numbers(const YAML::Node& node, const std::string& what);

// An OpenCV / ROS matrix map: `data`, with `rows` x `cols` matching when both are stated.
std::vector<double> MatrixNumbers(const YAML::Node& node, const std::string& what) {
  const std::optional<YAML::Node> data = Find(node, "data");
  if (!data) throw Problem(what + " is a map without 'data'" + LineOf(node));
  std::vector<double> values = Numbers(*data, what + ".data");
  const std::optional<YAML::Node> rows = Find(node, "rows");
  const std::optional<YAML::Node> cols = Find(node, "cols");
  if (rows && cols) {
    const int r = WholeNumber(*rows, what + ".rows");
    const int c = WholeNumber(*cols, what + ".cols");
    if (static_cast<size_t>(r) * static_cast<size_t>(c) != values.size()) {
      throw Problem(what + " says " + std::to_string(r) + "x" + std::to_string(c) + " but has " +
                    std::to_string(values.size()) + " values" + LineOf(node));
    }
  }
  return values;
}

// A list of numbers: a sequence, or a matrix map.
std::vector<double> Numbers(const YAML::Node& node, const std::string& what) {
  if (node.IsMap()) return MatrixNumbers(node, what);
  if (!node.IsSequence()) {
    throw Problem(what + " must be a list of numbers, got " + Shown(node) + LineOf(node));
  }
  std::vector<double> values;
  for (const YAML::Node& item : node) {
    const std::optional<double> value = AsNumber(item);
    if (!value) {
      throw Problem(what + " must contain numbers only, found " + Shown(item) + LineOf(item));
    }
    values.push_back(*value);
  }
  return values;
}

YAML::Node Require(const YAML::Node& map, const std::string& key, const std::string& format) {
  const std::optional<YAML::Node> node = Find(map, key);
  if (!node || node->IsNull()) throw Problem(Quote(key) + " is missing (" + format + ")");
  return *node;
}

std::string Text(const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar()) throw Problem(what + " must be a text, got " + Shown(node) + LineOf(node));
  return node.Scalar();
}

int PixelCount(double value, const std::string& what) {
  if (!(value >= 1 && value <= 1e6) || std::floor(value) != value) {
    std::ostringstream text;
    text << what << " must be a positive whole number of pixels, got " << value;
    throw Problem(text.str());
  }
  return static_cast<int>(value);
}

// Image size in pixels; 0 when the file does not state it.
int Size(const std::optional<YAML::Node>& node, const std::string& what) {
  if (!node) return 0;
  const std::optional<double> value = AsNumber(*node);
  if (!value) {
    throw Problem(what + " must be a number of pixels, got " + Shown(*node) + LineOf(*node));
  }
  return PixelCount(*value, what);
}

// fx fy cx cy from a row-major 3x3 camera matrix without skew.
void SetIntrinsics(const std::vector<double>& k, const std::string& what, CameraModel* camera) {
  if (k.size() != 9) {
    throw Problem(what + " must have 9 values (3x3), got " + std::to_string(k.size()));
  }
  if (std::abs(k[1]) > 1e-9 * std::abs(k[0])) {
    throw Problem(what + " has skew " + std::to_string(k[1]) + "; the camera models have none");
  }
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || std::abs(k[8] - 1) > 1e-12) {
    throw Problem(what + " is not of the form [fx 0 cx; 0 fy cy; 0 0 1]");
  }
  camera->fx = k[0];
  camera->fy = k[4];
  camera->cx = k[2];
  camera->cy = k[5];
}

// Sets the model from the name the file states and checks the coefficient count it implies.
void SetModel(const std::string& name, std::vector<double> coefficients, CameraModel* camera) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  // cv::calibrateCamera may return 12 or 14 values; beyond the 8th they are zero unless the
  // thin-prism or tilted models were asked for, which these models do not have.
  if ((coefficients.size() == 12 || coefficients.size() == 14) &&
      std::all_of(coefficients.begin() + 8, coefficients.end(), [](double v) { return v == 0; })) {
    coefficients.resize(8);
  }
  const size_t n = coefficients.size();
  if (lower == "plumb_bob" && n != 4 && n != 5) {
    throw Problem("plumb_bob needs 5 distortion coefficients (k1 k2 p1 p2 k3), got " +
                  std::to_string(n));
  }
  if (lower == "rational_polynomial" && n != 8) {
    throw Problem(
        "rational_polynomial needs 8 distortion coefficients (k1 k2 p1 p2 k3 k4 k5 k6), "
        "got " +
        std::to_string(n));
  }
  if (lower == "plumb_bob" || lower == "rational_polynomial" || lower == "radtan" ||
      lower == "pinhole-radtan" || lower == "radial-tangential") {
    camera->type = CameraModelType::kPinholeRadTan;
  } else if (lower == "equidistant" || lower == "fisheye" || lower == "kannala-brandt" ||
             lower == "kannala_brandt") {
    camera->type = CameraModelType::kKannalaBrandt;
  } else {
    throw Problem("distortion model " + Quote(name) +
                  " is unknown (known: plumb_bob, rational_polynomial, radtan, pinhole-radtan, "
                  "equidistant, fisheye, kannala-brandt)");
  }
  camera->distortion = std::move(coefficients);
}

// OpenCV FileStorage and ROS camera_calibration: camera_matrix + distortion_coefficients.
CameraModel FromCameraMatrix(const YAML::Node& root, bool opencv_file) {
  const std::string format = "OpenCV / ROS camera_calibration";
  CameraModel camera;
  SetIntrinsics(Numbers(Require(root, "camera_matrix", format), "camera_matrix"), "camera_matrix",
                &camera);
  const std::vector<double> coefficients =
      Numbers(Require(root, "distortion_coefficients", format), "distortion_coefficients");
  if (const std::optional<YAML::Node> model = Find(root, "distortion_model")) {
    SetModel(Text(*model, "distortion_model"), coefficients, &camera);
  } else if (opencv_file) {
    SetModel("pinhole-radtan", coefficients, &camera);  // what cv::calibrateCamera writes
  } else {
    throw Problem(
        "'distortion_model' is missing; only OpenCV FileStorage files (with their "
        "%YAML:1.0 header) imply pinhole-radtan");
  }
  camera.width = Size(Find(root, "image_width"), "image_width");
  camera.height = Size(Find(root, "image_height"), "image_height");
  return camera;
}

// The ROS sensor_msgs/CameraInfo fields (ROS 1 upper case, ROS 2 lower case).
CameraModel FromCameraInfo(const YAML::Node& root) {
  const std::string format = "ROS CameraInfo";
  const bool upper = Find(root, "K").has_value();
  CameraModel camera;
  SetIntrinsics(Numbers(Require(root, upper ? "K" : "k", format), "K"), "K", &camera);
  SetModel(Text(Require(root, "distortion_model", format), "distortion_model"),
           Numbers(Require(root, upper ? "D" : "d", format), "D"), &camera);
  camera.width = Size(Find(root, "width"), "width");
  camera.height = Size(Find(root, "height"), "height");
  return camera;
}

// Kalibr's distortion: radtan / equidistant with distortion_coeffs, or none without them.
void SetKalibrDistortion(const YAML::Node& cam, const std::string& format, CameraModel* camera) {
  const std::string model = Text(Require(cam, "distortion_model", format), "distortion_model");
  const std::optional<YAML::Node> coefficients_node = Find(cam, "distortion_coeffs");
  std::vector<double> coefficients;
  if (coefficients_node) coefficients = Numbers(*coefficients_node, "distortion_coeffs");
  if (model == "none") {
    if (!coefficients.empty()) throw Problem("distortion_model none with distortion_coeffs");
    SetModel("radtan", {0, 0, 0, 0}, camera);
  } else {
    if (!coefficients_node) throw Problem("'distortion_coeffs' is missing (" + format + ")");
    SetModel(model, coefficients, camera);
  }
}

// A Kalibr camchain camera: pinhole intrinsics [fu fv pu pv], radtan / equidistant / none.
CameraModel FromKalibr(const YAML::Node& cam, const std::string& name) {
  const std::string format = "Kalibr " + name;
  const std::string projection = Text(Require(cam, "camera_model", format), "camera_model");
  if (projection != "pinhole") {
    throw Problem(name + " camera_model " + Quote(projection) +
                  " is not supported (only pinhole, with radtan or equidistant distortion)");
  }
  const std::vector<double> intrinsics = Numbers(Require(cam, "intrinsics", format), "intrinsics");
  if (intrinsics.size() != 4) {
    throw Problem(name + " intrinsics must be [fu, fv, pu, pv], got " +
                  std::to_string(intrinsics.size()) + " values");
  }
  CameraModel camera;
  camera.fx = intrinsics[0];
  camera.fy = intrinsics[1];
  camera.cx = intrinsics[2];
  camera.cy = intrinsics[3];
  SetKalibrDistortion(cam, format, &camera);
  if (const std::optional<YAML::Node> resolution = Find(cam, "resolution")) {
    const std::vector<double> size = Numbers(*resolution, "resolution");
    if (size.size() != 2) throw Problem("resolution must be [width, height]");
    camera.width = PixelCount(size[0], "resolution width");
    camera.height = PixelCount(size[1], "resolution height");
  }
  return camera;
}

CameraModel Interpret(const YAML::Node& root, bool opencv_file) {
  if (!root.IsMap()) {
    throw Problem("not a camera file: expected a map of named parameters at the top level");
  }
  CameraModel camera;
  if (const std::optional<YAML::Node> cam0 = Find(root, "cam0")) {
    camera = FromKalibr(*cam0, "cam0");
  } else if (Find(root, "camera_model") && Find(root, "intrinsics")) {
    camera = FromKalibr(root, "camera");
  } else if (Find(root, "camera_matrix")) {
    camera = FromCameraMatrix(root, opencv_file);
  } else if (Find(root, "K") || Find(root, "k")) {
    camera = FromCameraInfo(root);
  } else {
    throw Problem(
        "cannot tell the format: none of camera_matrix (OpenCV, ROS camera_calibration),"
        " K (ROS CameraInfo) or cam0 (Kalibr) is present");
  }
  // Calibench's own key (every format): the covariance of [fx fy cx cy distortion...] that
  // `calibench intrinsics` estimated; other tools ignore it.
  const YAML::Node& holder = Find(root, "cam0") ? *Find(root, "cam0") : root;
  if (const std::optional<YAML::Node> covariance = Find(holder, "intrinsics_covariance"))
    camera.covariance = Numbers(*covariance, "intrinsics_covariance");
  // The size may be absent (0 = unknown); everything else must already be valid.
  CameraModel sized = camera;
  if (sized.width == 0) sized.width = 1;
  if (sized.height == 0) sized.height = 1;
  std::string why;
  if (!sized.Check(&why)) throw Problem(why);
  return camera;
}

}  // namespace

CameraModel LoadCameraFile(const std::filesystem::path& path) {
  try {
    const std::string text = ReadText(path);
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '<') {
      CheckXmlNesting(text);
      return Interpret(ReadOpenCvXml(text), /*opencv_file=*/true);
    }
    CheckYamlText(text);
    // OpenCV's FileStorage writes this header (not valid YAML 1.x; yaml-cpp skips it).
    const bool opencv_file = text.starts_with("%YAML:1.");
    return Interpret(ParseYaml(text), opencv_file);
  } catch (const Problem& problem) {
    throw IoError("camera file '" + path.string() + "': " + problem.what());
  }
}

CameraModel CameraFromCameraInfo(const std::string& distortion_model, int width, int height,
                                 const double (&k)[9], const std::vector<double>& d) {
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.fx = k[0];
  camera.fy = k[4];
  camera.cx = k[2];
  camera.cy = k[5];
  try {
    SetModel(distortion_model, d, &camera);
  } catch (const Problem& problem) {
    throw std::invalid_argument(problem.what());
  }
  std::string why;
  if (!camera.Check(&why)) throw std::invalid_argument("intrinsics: " + why);
  return camera;
}

void SaveCameraInfoYaml(const std::filesystem::path& path, const CameraModel& camera,
                        const std::string& camera_name) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  const bool fisheye = camera.type == CameraModelType::kKannalaBrandt;
  const std::string model = fisheye                         ? "equidistant"
                            : camera.distortion.size() == 8 ? "rational_polynomial"
                                                            : "plumb_bob";
  auto matrix = [&](const char* name, int rows, int cols, const std::vector<double>& data) {
    out << YAML::Key << name << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "rows" << YAML::Value << rows << YAML::Key << "cols" << YAML::Value << cols;
    out << YAML::Key << "data" << YAML::Value << YAML::Flow << data << YAML::EndMap;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << camera.width;
  out << YAML::Key << "image_height" << YAML::Value << camera.height;
  out << YAML::Key << "camera_name" << YAML::Value << camera_name;
  matrix("camera_matrix", 3, 3, {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1});
  out << YAML::Key << "distortion_model" << YAML::Value << model;
  matrix("distortion_coefficients", 1, static_cast<int>(camera.distortion.size()),
         camera.distortion);
  matrix("rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  matrix("projection_matrix", 3, 4,
         {camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0});
  if (!camera.covariance.empty()) {
    const int n = static_cast<int>(4 + camera.distortion.size());
    matrix("intrinsics_covariance", n, n, camera.covariance);
  }
  out << YAML::EndMap;
  WriteFileAtomically(path, std::string(out.c_str()) + "\n");
}

}  // namespace calibench
