// LoadCameraFile (core/dataset.h): intrinsics from OpenCV FileStorage, ROS camera_calibration /
// CameraInfo YAML and Kalibr camchain files. Every file is first turned into a YamlNode tree
// (cv::FileStorage for what OpenCV reads, the YAML subset reader for the rest), then one
// interpreter picks the format by its keys.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>

#include "core/io/dataset.h"
#include "core/io/camera_file.h"
#include "core/io/yaml_lite.h"

namespace calibench {
namespace {

// Camera files are a few kilobytes; anything far larger is not one.
constexpr std::uintmax_t kMaxFileBytes = 16 << 20;

// A problem with the file's content; LoadCameraFile adds the file name.
class Problem : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

std::string Quote(const std::string& s) { return "'" + s + "'"; }

YamlNode FromFileNode(const cv::FileNode& node) {
  YamlNode out;
  if (node.isMap() || node.isSeq()) {
    out.kind = node.isMap() ? YamlNode::Kind::kMap : YamlNode::Kind::kSequence;
    for (cv::FileNodeIterator it = node.begin(); it != node.end(); ++it) {
      const cv::FileNode child = *it;
      if (node.isMap()) {
        out.entries.emplace_back(child.name(), FromFileNode(child));
      } else {
        out.items.push_back(FromFileNode(child));
      }
    }
  } else if (node.isInt() || node.isReal()) {
    char buffer[64];
    // Shortest text that reads back as the same double: no digits lost on the way.
    const double value =
        node.isInt() ? static_cast<double>(static_cast<int>(node)) : static_cast<double>(node);
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    out.kind = YamlNode::Kind::kScalar;
    out.scalar.assign(buffer, result.ptr);
  } else if (node.isString()) {
    out.kind = YamlNode::Kind::kScalar;
    out.scalar = static_cast<std::string>(node);
    out.quoted = true;
  }
  return out;
}

// The file read by cv::FileStorage (OpenCV's YAML with its %YAML:1.0 header, XML, JSON);
// nullopt with OpenCV's reason when it does not take it.
std::optional<YamlNode> ReadWithOpenCv(const std::filesystem::path& path, std::string* why) {
  try {
    cv::FileStorage storage(path.string(), cv::FileStorage::READ);
    if (!storage.isOpened()) {
      *why = "OpenCV could not open it";
      return std::nullopt;
    }
    return FromFileNode(storage.root());
  } catch (const cv::Exception& e) {
    // OpenCV's parsers put "file(line): problem" in `func` and their own name in `err`.
    *why = e.code == cv::Error::StsParseError ? e.func : e.err;
    return std::nullopt;
  }
}

std::string ReadText(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw Problem("no such file");
  if (!std::filesystem::is_regular_file(path, error)) throw Problem("not a regular file");
  if (std::filesystem::file_size(path, error) > kMaxFileBytes) {
    throw Problem("larger than 16 MiB, not a camera file");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw Problem("cannot be read");
  return text.str();
}

// A list of numbers: a sequence, or a matrix map with `data` (and rows x cols matching).
std::vector<double> Numbers(const YamlNode& node, const std::string& what) {
  if (node.kind == YamlNode::Kind::kMap) {
    const YamlNode* data = node.Find("data");
    if (!data) throw Problem(what + " is a map without 'data'");
    std::vector<double> values = Numbers(*data, what + ".data");
    const YamlNode* rows = node.Find("rows");
    const YamlNode* cols = node.Find("cols");
    if (rows && cols && rows->AsDouble() && cols->AsDouble() &&
        *rows->AsDouble() * *cols->AsDouble() != static_cast<double>(values.size())) {
      throw Problem(what + " says " + rows->scalar + "x" + cols->scalar + " but has " +
                    std::to_string(values.size()) + " values");
    }
    return values;
  }
  if (node.kind != YamlNode::Kind::kSequence) {
    throw Problem(what + " must be a list of numbers (line " + std::to_string(node.line) + ")");
  }
  std::vector<double> values;
  for (const YamlNode& item : node.items) {
    const std::optional<double> value = item.AsDouble();
    if (!value) {
      throw Problem(what + " must contain numbers only, found " + Quote(item.scalar) + " (line " +
                    std::to_string(item.line) + ")");
    }
    values.push_back(*value);
  }
  return values;
}

const YamlNode& Require(const YamlNode& map, const std::string& key, const std::string& format) {
  const YamlNode* node = map.Find(key);
  if (!node || node->kind == YamlNode::Kind::kNull) {
    throw Problem("'" + key + "' is missing (" + format + ")");
  }
  return *node;
}

std::string Text(const YamlNode& node, const std::string& what) {
  if (node.kind != YamlNode::Kind::kScalar) throw Problem(what + " must be a text");
  return node.scalar;
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
int Size(const YamlNode* node, const std::string& what) {
  if (!node) return 0;
  const std::optional<double> value = node->AsDouble();
  if (!value) throw Problem(what + " must be a number of pixels, got " + Quote(node->scalar));
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
CameraModel FromCameraMatrix(const YamlNode& root, bool opencv_file) {
  const std::string format = "OpenCV / ROS camera_calibration";
  CameraModel camera;
  SetIntrinsics(Numbers(Require(root, "camera_matrix", format), "camera_matrix"), "camera_matrix",
                &camera);
  const std::vector<double> coefficients =
      Numbers(Require(root, "distortion_coefficients", format), "distortion_coefficients");
  const YamlNode* model = root.Find("distortion_model");
  if (model) {
    SetModel(Text(*model, "distortion_model"), coefficients, &camera);
  } else if (opencv_file) {
    SetModel("pinhole-radtan", coefficients, &camera);  // what cv::calibrateCamera writes
  } else {
    throw Problem(
        "'distortion_model' is missing; only OpenCV FileStorage files (with their "
        "%YAML:1.0 header) imply pinhole-radtan");
  }
  camera.width = Size(root.Find("image_width"), "image_width");
  camera.height = Size(root.Find("image_height"), "image_height");
  return camera;
}

// The ROS sensor_msgs/CameraInfo fields (ROS 1 upper case, ROS 2 lower case).
CameraModel FromCameraInfo(const YamlNode& root) {
  const std::string format = "ROS CameraInfo";
  const bool upper = root.Find("K") != nullptr;
  CameraModel camera;
  SetIntrinsics(Numbers(Require(root, upper ? "K" : "k", format), "K"), "K", &camera);
  SetModel(Text(Require(root, "distortion_model", format), "distortion_model"),
           Numbers(Require(root, upper ? "D" : "d", format), "D"), &camera);
  camera.width = Size(root.Find("width"), "width");
  camera.height = Size(root.Find("height"), "height");
  return camera;
}

// A Kalibr camchain camera: pinhole intrinsics [fu fv pu pv], radtan / equidistant / none.
CameraModel FromKalibr(const YamlNode& cam, const std::string& name) {
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
  const std::string model = Text(Require(cam, "distortion_model", format), "distortion_model");
  const YamlNode* coefficients_node = cam.Find("distortion_coeffs");
  std::vector<double> coefficients;
  if (coefficients_node) coefficients = Numbers(*coefficients_node, "distortion_coeffs");
  if (model == "none") {
    if (!coefficients.empty()) throw Problem("distortion_model none with distortion_coeffs");
    SetModel("radtan", {0, 0, 0, 0}, &camera);
  } else {
    if (!coefficients_node) throw Problem("'distortion_coeffs' is missing (" + format + ")");
    SetModel(model, coefficients, &camera);
  }
  if (const YamlNode* resolution = cam.Find("resolution")) {
    const std::vector<double> size = Numbers(*resolution, "resolution");
    if (size.size() != 2) throw Problem("resolution must be [width, height]");
    camera.width = PixelCount(size[0], "resolution width");
    camera.height = PixelCount(size[1], "resolution height");
  }
  return camera;
}

CameraModel Interpret(const YamlNode& root, bool opencv_file) {
  if (root.kind != YamlNode::Kind::kMap) {
    throw Problem("not a camera file: expected a map of named parameters at the top level");
  }
  CameraModel camera;
  if (const YamlNode* cam0 = root.Find("cam0")) {
    camera = FromKalibr(*cam0, "cam0");
  } else if (root.Find("camera_model") && root.Find("intrinsics")) {
    camera = FromKalibr(root, "camera");
  } else if (root.Find("camera_matrix")) {
    camera = FromCameraMatrix(root, opencv_file);
  } else if (root.Find("K") || root.Find("k")) {
    camera = FromCameraInfo(root);
  } else {
    throw Problem(
        "cannot tell the format: none of camera_matrix (OpenCV, ROS camera_calibration),"
        " K (ROS CameraInfo) or cam0 (Kalibr) is present");
  }
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
    std::string opencv_why;
    if (std::optional<YamlNode> root = ReadWithOpenCv(path, &opencv_why)) {
      return Interpret(*root, /*opencv_file=*/true);
    }
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '<') {
      throw Problem("OpenCV cannot read this XML file: " + opencv_why);
    }
    std::string yaml_why;
    const std::optional<YamlNode> root = ParseYamlLite(text, &yaml_why);
    if (!root) throw Problem("not valid YAML: " + yaml_why);
    return Interpret(*root, /*opencv_file=*/false);
  } catch (const Problem& problem) {
    throw IoError("camera file '" + path.string() + "': " + problem.what());
  }
}

}  // namespace calibench
