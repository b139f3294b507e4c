// LoadCameraFile on every supported format (written here, and the real files in ../shared), and
// on bad inputs, which must throw IoError naming the file (and the line, where there is one),
// deeply nested ones included.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>

#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

std::filesystem::path Write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

void ExpectCamera(const CameraModel& c, CameraModelType type, int width, int height, double fx,
                  double fy, double cx, double cy, const std::vector<double>& distortion) {
  EXPECT_EQ(c.type, type);
  EXPECT_EQ(c.width, width);
  EXPECT_EQ(c.height, height);
  EXPECT_EQ(c.fx, fx);
  EXPECT_EQ(c.fy, fy);
  EXPECT_EQ(c.cx, cx);
  EXPECT_EQ(c.cy, cy);
  EXPECT_EQ(c.distortion, distortion);
}

// Writes an OpenCV FileStorage file as cv::calibrateCamera users do.
void WriteOpenCv(const std::filesystem::path& path, const cv::Mat& k, const cv::Mat& d,
                 const std::string& model, int width, int height) {
  cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
  if (width > 0) storage << "image_width" << width << "image_height" << height;
  storage << "camera_matrix" << k << "distortion_coefficients" << d;
  if (!model.empty()) storage << "distortion_model" << model;
}

cv::Mat CharucoK() {
  return (cv::Mat_<double>(3, 3) << 452.51072219637672, 0, 317.70297317353277, 0,
          456.76707935146891, 277.75155919135995, 0, 0, 1);
}

TEST(CameraFileTest, OpenCvYamlAndXml) {
  const std::filesystem::path dir = test::TempDir("camera_file_opencv");
  const std::vector<double> d = {0.12136925618707872, -1.0854664722560681, 1.178684379666846e-04,
                                 -4.6240686046485508e-04, 2.954258940681008};
  WriteOpenCv(dir / "camera.yaml", CharucoK(), cv::Mat(d).t(), "", 640, 480);
  ExpectCamera(LoadCameraFile(dir / "camera.yaml"), CameraModelType::kPinholeRadTan, 640, 480,
               452.51072219637672, 456.76707935146891, 317.70297317353277, 277.75155919135995, d);

  const std::vector<double> fisheye = {-0.0540096, -0.0784275, 0.0959641, -0.0515253};
  WriteOpenCv(dir / "camera.xml", CharucoK(), cv::Mat(fisheye), "fisheye", 1920, 1208);
  ExpectCamera(LoadCameraFile(dir / "camera.xml"), CameraModelType::kKannalaBrandt, 1920, 1208,
               452.51072219637672, 456.76707935146891, 317.70297317353277, 277.75155919135995,
               fisheye);

  // cv::calibrateCamera's 14 values with thin-prism/tilt terms zero are the rational model; the
  // size may be absent (0 = unknown).
  std::vector<double> fourteen = {0.61, -0.045, 8e-4, -4e-4, -0.0021, 0.98, 0.11, -0.0089};
  fourteen.resize(14, 0.0);
  WriteOpenCv(dir / "rational.yml", CharucoK(), cv::Mat(fourteen), "", 0, 0);
  const CameraModel rational = LoadCameraFile(dir / "rational.yml");
  EXPECT_EQ(rational.distortion,
            (std::vector<double>{0.61, -0.045, 8e-4, -4e-4, -0.0021, 0.98, 0.11, -0.0089}));
  EXPECT_EQ(rational.width, 0);
  EXPECT_EQ(rational.height, 0);
}

TEST(CameraFileTest, RosCameraCalibrationYaml) {
  const std::filesystem::path dir = test::TempDir("camera_file_ros");
  const auto path = Write(dir / "ost.yaml",
                          "image_width: 1280\n"
                          "image_height: 800\n"
                          "camera_name: wide\n"
                          "camera_matrix:\n"
                          "  rows: 3\n"
                          "  cols: 3\n"
                          "  data: [610.2, 0, 641.3, 0, 609.8, 398.7, 0, 0, 1]\n"
                          "distortion_model: rational_polynomial\n"
                          "distortion_coefficients:\n"
                          "  rows: 1\n"
                          "  cols: 8\n"
                          "  data: [0.61, -0.045, 0.0008, -0.0004, -0.0021, 0.98, 0.11, -0.0089]\n"
                          "rectification_matrix:\n"
                          "  rows: 3\n"
                          "  cols: 3\n"
                          "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n");
  ExpectCamera(LoadCameraFile(path), CameraModelType::kPinholeRadTan, 1280, 800, 610.2, 609.8,
               641.3, 398.7, {0.61, -0.045, 0.0008, -0.0004, -0.0021, 0.98, 0.11, -0.0089});
}

TEST(CameraFileTest, RosCameraInfoFields) {
  const std::filesystem::path dir = test::TempDir("camera_file_camera_info");
  const auto ros1 = Write(dir / "info.yaml",
                          "header:\n"
                          "  seq: 0\n"
                          "  frame_id: 'camera'\n"
                          "height: 1024\n"
                          "width: 1280\n"
                          "distortion_model: \"equidistant\"\n"
                          "D: [0.02, -0.004, 0.0006, -5.0e-05]\n"
                          "K: [330.5, 0.0, 640.25, 0.0, 331.5, 512.75, 0.0, 0.0, 1.0]\n"
                          "R: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
                          "binning_x: 0\n"
                          "---\n");
  ExpectCamera(LoadCameraFile(ros1), CameraModelType::kKannalaBrandt, 1280, 1024, 330.5, 331.5,
               640.25, 512.75, {0.02, -0.004, 0.0006, -5.0e-05});
  // ROS 2 spells the fields in lower case.
  const auto ros2 = Write(dir / "info2.yaml",
                          "height: 480\nwidth: 640\ndistortion_model: plumb_bob\n"
                          "d: [-0.1, 0.05, 0.001, -0.002, 0.0]\n"
                          "k: [500, 0, 320, 0, 501, 240, 0, 0, 1]\n");
  ExpectCamera(LoadCameraFile(ros2), CameraModelType::kPinholeRadTan, 640, 480, 500, 501, 320, 240,
               {-0.1, 0.05, 0.001, -0.002, 0.0});
}

TEST(CameraFileTest, KalibrCamchain) {
  const std::filesystem::path dir = test::TempDir("camera_file_kalibr");
  const auto radtan = Write(dir / "camchain.yaml",
                            "cam0:\n"
                            "  T_cam_imu:\n"
                            "  - [0.0148655429818, -0.999880929698, 0.00414029679422, -0.02164]\n"
                            "  - [0.0, 0.0, 0.0, 1.0]\n"
                            "  cam_overlaps: [1]\n"
                            "  camera_model: pinhole\n"
                            "  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359,\n"
                            "    1.76187114e-05]\n"
                            "  distortion_model: radtan\n"
                            "  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
                            "  resolution: [752, 480]\n"
                            "  rostopic: /cam0/image_raw\n"
                            "cam1:\n"
                            "  camera_model: omni\n");
  ExpectCamera(LoadCameraFile(radtan), CameraModelType::kPinholeRadTan, 752, 480, 458.654, 457.296,
               367.215, 248.375, {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
  const auto equidistant = Write(dir / "equidistant.yaml",
                                 "cam0:\n"
                                 "  camera_model: pinhole\n"
                                 "  intrinsics: [1176.93, 1177.72, 962.275, 612.725]\n"
                                 "  distortion_model: equidistant\n"
                                 "  distortion_coeffs: [-0.0540096, -0.0784275, 0.0959641, "
                                 "-0.0515253]\n"
                                 "  resolution: [1920, 1208]\n");
  ExpectCamera(LoadCameraFile(equidistant), CameraModelType::kKannalaBrandt, 1920, 1208, 1176.93,
               1177.72, 962.275, 612.725, {-0.0540096, -0.0784275, 0.0959641, -0.0515253});
  const auto none = Write(dir / "none.yaml",
                          "cam0:\n  camera_model: pinhole\n  distortion_model: none\n"
                          "  intrinsics: [400, 401, 320, 240]\n  resolution: [640, 480]\n");
  ExpectCamera(LoadCameraFile(none), CameraModelType::kPinholeRadTan, 640, 480, 400, 401, 320, 240,
               {0, 0, 0, 0});
}

// The YAML that real camera files use beyond the plain shapes above: CRLF, comments, quotes
// holding ':' and '#', anchors and aliases, block scalars, lists of maps, a YAML 1.2 header.
TEST(CameraFileTest, YamlSyntaxInCameraFiles) {
  const std::filesystem::path dir = test::TempDir("camera_file_yaml_syntax");
  const auto ros = Write(dir / "info.yaml",
                         "%YAML 1.2\r\n"
                         "---\r\n"
                         "# a CameraInfo, hand-edited\r\n"
                         "header: {frame_id: \"cam #1: left\", stamp: {sec: 0}}\r\n"
                         "note: |\r\n"
                         "  don't [parse { this\r\n"
                         "    - as: structure\r\n"
                         "roi:\r\n"
                         "- name: 'it''s full'\r\n"
                         "  size: &size [640, 480]\r\n"
                         "- same: *size\r\n"
                         "width: 640  # pixels\r\n"
                         "height: 480\r\n"
                         "distortion_model: 'plumb_bob'\r\n"
                         "D: [-0.1, 0.05,\r\n"
                         "    0.001, -0.002, 0.0]\r\n"
                         "K: [500, 0, 320,\r\n"
                         "    0, 501, 240,\r\n"
                         "    0, 0, 1]\r\n"
                         "extra: " +
                             std::string(60, '[') + std::string(60, ']') + "\r\n");
  ExpectCamera(LoadCameraFile(ros), CameraModelType::kPinholeRadTan, 640, 480, 500, 501, 320, 240,
               {-0.1, 0.05, 0.001, -0.002, 0.0});
  // OpenCV's own header, tags and line-wrapped matrices, written by hand: the model is implied.
  const auto opencv = Write(dir / "opencv.yml",
                            "%YAML:1.0\n"
                            "---\n"
                            "calibration_time: \"Wed 08 Dec 2021 05:13:09 PM MSK\"\n"
                            "camera_matrix: !!opencv-matrix\n"
                            "   rows: 3\n"
                            "   cols: 3\n"
                            "   dt: d\n"
                            "   data: [ 4.5251072219637672e+02, 0., 3.1770297317353277e+02, 0.,\n"
                            "       4.5676707935146891e+02, 2.7775155919135995e+02, 0., 0., 1. ]\n"
                            "distortion_coefficients: !!opencv-matrix\n"
                            "   rows: 1\n"
                            "   cols: 4\n"
                            "   dt: d\n"
                            "   data: [ .5, -.25, 0., 0. ]\n");
  ExpectCamera(LoadCameraFile(opencv), CameraModelType::kPinholeRadTan, 0, 0, 452.51072219637672,
               456.76707935146891, 317.70297317353277, 277.75155919135995, {0.5, -0.25, 0, 0});
}

TEST(CameraFileTest, SharedDatasetFiles) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const std::filesystem::path datasets = shared / "datasets";
  ExpectCamera(LoadCameraFile(datasets / "acfr-vlp16-chessboard" / "camera_info.yaml"),
               CameraModelType::kKannalaBrandt, 1920, 1208, 1176.93, 1177.72, 962.275, 612.725,
               {-0.0540096, -0.0784275, 0.0959641, -0.0515253});
  ExpectCamera(LoadCameraFile(datasets / "udacity-chessboard-intrinsics" / "ost.yaml"),
               CameraModelType::kPinholeRadTan, 964, 724, 484.130454, 484.452449, 457.177461,
               364.861413, {-0.199619, 0.068964, 0.003371, 0.000296, 0.0});
  ExpectCamera(
      LoadCameraFile(datasets / "opencv-charuco-intrinsics" / "tutorial_camera_charuco.yml"),
      CameraModelType::kPinholeRadTan, 640, 480, 4.5251072219637672e+02, 4.5676707935146891e+02,
      3.1770297317353277e+02, 2.7775155919135995e+02,
      {1.2136925618707872e-01, -1.0854664722560681e+00, 1.1786843796668460e-04,
       -4.6240686046485508e-04, 2.9542589406810080e+00});
}

// LoadCameraFile(path) throws IoError naming the file and containing `problem`.
void ExpectRejected(const std::filesystem::path& path, const std::string& problem) {
  try {
    LoadCameraFile(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << "expected '" << problem << "' in: " << what;
  }
}

TEST(CameraFileTest, BadInputsThrowIoErrorNamingTheFile) {
  const std::filesystem::path dir = test::TempDir("camera_file_bad");
  const std::string k = "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\nwidth: 640\nheight: 480\n";
  ExpectRejected(dir / "missing.yaml", "no such file");
  ExpectRejected(dir, "not a regular file");
  ExpectRejected(Write(dir / "empty.yaml", ""), "expected a map");
  ExpectRejected(Write(dir / "garbage.yaml", "camera: [1, 2\n  oops: {"), "not valid YAML");
  ExpectRejected(Write(dir / "binary.yaml", std::string("\x89PNG\r\n\x1a\n\0\0", 10)), "binary");
  ExpectRejected(Write(dir / "text.yaml", "just some words\n"), "expected a map");
  ExpectRejected(Write(dir / "other.yaml", "width: 640\nheight: 480\n"), "cannot tell the format");
  ExpectRejected(Write(dir / "broken.xml", "<?xml version=\"1.0\"?>\n<opencv_storage><a>"), "XML");
  ExpectRejected(Write(dir / "unknown.yaml", k + "distortion_model: mei\nD: [1, 2, 3, 4]\n"),
                 "distortion model 'mei' is unknown");
  ExpectRejected(Write(dir / "no_model.yaml", k + "D: [0, 0, 0, 0, 0]\n"),
                 "'distortion_model' is missing");
  ExpectRejected(
      Write(dir / "fisheye5.yaml", k + "distortion_model: fisheye\nD: [0, 0, 0, 0, 0]\n"),
      "kannala-brandt needs exactly 4 distortion coefficients (k1 k2 k3 k4), got 5");
  ExpectRejected(
      Write(dir / "plumb8.yaml", k + "distortion_model: plumb_bob\nD: [0,0,0,0,0,0,0,0]\n"),
      "plumb_bob needs 5");
  ExpectRejected(Write(dir / "rational5.yaml",
                       k + "distortion_model: rational_polynomial\nD: [0, 0, 0, 0, 0]\n"),
                 "rational_polynomial needs 8");
  ExpectRejected(Write(dir / "radtan3.yaml", k + "distortion_model: radtan\nD: [0, 0, 0]\n"),
                 "got 3");
  ExpectRejected(Write(dir / "text_value.yaml", k + "distortion_model: radtan\nD: [0, a, 0, 0]\n"),
                 "numbers only");
  ExpectRejected(Write(dir / "skew.yaml",
                       "K: [500, 2, 320, 0, 500, 240, 0, 0, 1]\n"
                       "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"),
                 "skew");
  ExpectRejected(Write(dir / "k8.yaml",
                       "K: [500, 0, 320, 0, 500, 240, 0, 0]\n"
                       "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"),
                 "9 values");
  ExpectRejected(Write(dir / "fx0.yaml",
                       "K: [0, 0, 320, 0, 500, 240, 0, 0, 1]\n"
                       "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"),
                 "fx=0");
  ExpectRejected(Write(dir / "width.yaml",
                       "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\nwidth: -5\n"
                       "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"),
                 "width must be a positive whole number");
  ExpectRejected(Write(dir / "omni.yaml",
                       "cam0:\n  camera_model: omni\n"
                       "  intrinsics: [0.8, 400, 400, 320, 240]\n"),
                 "camera_model 'omni' is not supported");
  ExpectRejected(Write(dir / "ros_no_model.yaml",
                       "camera_matrix:\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
                       "distortion_coefficients:\n  data: [0, 0, 0, 0, 0]\n"),
                 "'distortion_model' is missing");
  ExpectRejected(Write(dir / "rows.yaml",
                       "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 320, 0, 500, 240]\n"
                       "distortion_model: plumb_bob\n"
                       "distortion_coefficients:\n  data: [0, 0, 0, 0, 0]\n"),
                 "3x3 but has 6 values");

  // The same wrong count through OpenCV FileStorage.
  WriteOpenCv(dir / "opencv_fisheye5.yml", CharucoK(), cv::Mat(std::vector<double>(5, 0.0)),
              "fisheye", 640, 480);
  ExpectRejected(dir / "opencv_fisheye5.yml", "got 5");
  WriteOpenCv(dir / "opencv_unknown.yml", CharucoK(), cv::Mat(std::vector<double>(4, 0.0)), "mei",
              640, 480);
  ExpectRejected(dir / "opencv_unknown.yml", "'mei' is unknown");
}

TEST(CameraFileTest, ErrorsNameTheLine) {
  const std::filesystem::path dir = test::TempDir("camera_file_lines");
  const std::string k = "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n";
  const std::string model = "distortion_model: plumb_bob\n";
  ExpectRejected(Write(dir / "indent.yaml", k + "width: 640\n  height: 480\n"),
                 "not valid YAML: line 3");
  ExpectRejected(Write(dir / "tab.yaml", "header:\n\tseq: 0\n" + k), "not valid YAML: line 2");
  // yaml-cpp 0.7 would let an unclosed quote run to the end of the file.
  ExpectRejected(Write(dir / "quote.yaml", k + "distortion_model: \"plumb_bob\nD: [0, 0]\n"),
                 "not valid YAML: line 2: the quote is never closed");
  ExpectRejected(Write(dir / "quote1.yaml", k + "distortion_model: 'plumb_bob\nD: [0, 0]\n"),
                 "not valid YAML: line 2: the quote is never closed");
  ExpectRejected(Write(dir / "bracket.yaml", k + model + "D: [0, 0, 0, 0, 0\nwidth: 640\n"),
                 "not valid YAML: line 4");
  ExpectRejected(Write(dir / "alias.yaml", k + model + "D: *coefficients\n"),
                 "not valid YAML: line 3");
  ExpectRejected(Write(dir / "twice.yaml", k + model + "D: [0, 0, 0, 0, 0]\n" + k),
                 "'K' is given twice (line 4)");
  ExpectRejected(
      Write(dir / "twice_inner.yaml", "cam0:\n  camera_model: pinhole\n  camera_model: omni\n"),
      "'camera_model' is given twice (line 3)");
  ExpectRejected(Write(dir / "text_value.yaml", k + model + "D: [0, a, 0, 0, 0]\n"),
                 "D must contain numbers only, found 'a' (line 3)");
  for (const char* number : {"0x10", "1.0abc", "--1", "1e", "~", "", "[1]"}) {
    ExpectRejected(Write(dir / "number.yaml", k + model + "D: [0, " + number + ", 0, 0, 0]\n"),
                   "D must contain numbers only");
  }
  ExpectRejected(Write(dir / "width_list.yaml", k + model + "D: [0, 0, 0, 0, 0]\nwidth: [640]\n"),
                 "width must be a number of pixels, got a list (line 4)");
  ExpectRejected(Write(dir / "model_list.yaml", k + "distortion_model: [a]\nD: [0, 0, 0, 0, 0]\n"),
                 "distortion_model must be a text, got a list (line 2)");
  ExpectRejected(Write(dir / "d_text.yaml", k + model + "D: none\n"),
                 "D must be a list of numbers, got 'none' (line 3)");
  ExpectRejected(Write(dir / "rows.yaml",
                       "camera_matrix:\n  rows: three\n  cols: 3\n"
                       "  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n" +
                           model + "distortion_coefficients: [0, 0, 0, 0, 0]\n"),
                 "camera_matrix.rows must be a whole number, got 'three' (line 2)");
  ExpectRejected(Write(dir / "opencv_broken.yml",
                       "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n"
                       "   data: [ 1., 0.,\n"),
                 "not valid YAML: line 6");
  ExpectRejected(Write(dir / "control.yaml", k + "note: bell\a\n"), "binary data");
}

// Both parsers recurse; nesting is measured on the text first, so even 100,000 levels end in an
// IoError, not a stack overflow.
TEST(CameraFileTest, DeepNestingIsRefusedBeforeParsing) {
  const std::filesystem::path dir = test::TempDir("camera_file_nesting");
  const std::string k = "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n";
  const std::string deep = "nested deeper than 64 levels";
  const int n = 100000;
  const auto repeat = [](const std::string& s, int times) {
    std::string out;
    for (int i = 0; i < times; ++i) out += s;
    return out;
  };
  ExpectRejected(Write(dir / "flow.yaml", k + "x: " + repeat("[", n) + repeat("]", n) + "\n"),
                 deep + " (line 2)");
  ExpectRejected(Write(dir / "flow_map.yaml", repeat("{a: ", n) + "1" + repeat("}", n)), deep);
  ExpectRejected(Write(dir / "flow_lines.yaml", "x:\n" + repeat("  [\n", n)), deep);
  ExpectRejected(Write(dir / "compact.yaml", repeat("- ", n) + "x\n"), deep);
  ExpectRejected(Write(dir / "opencv.yml", "%YAML:1.0\n---\nx: " + repeat("[", n)), deep);
  std::string indented;
  for (int i = 0; i < 70; ++i) indented += std::string(i, ' ') + "k" + std::to_string(i) + ":\n";
  ExpectRejected(Write(dir / "indented.yaml", indented), deep + " (line 65)");
  std::string sequences = "k:\n";  // sequences at their key's indentation nest too
  for (int i = 0; i < 40; ++i) sequences += std::string(2 * i, ' ') + "- k:\n";
  ExpectRejected(Write(dir / "sequences.yaml", sequences), deep);
  ExpectRejected(Write(dir / "deep.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n" +
                                             repeat("<a x=\"/>\">", n) + repeat("</a>", n) +
                                             "\n</opencv_storage>\n"),
                 deep + " (line 3)");
  // Brackets in quotes, comments and block scalars are text, not nesting.
  const std::string text = repeat("[", 100);
  ExpectCamera(LoadCameraFile(
                   Write(dir / "text.yaml", k +
                                                "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"
                                                "a: '" +
                                                text + "'\nb: \"" + text + "\"\n# " + text +
                                                "\nc: |\n  " + text + "\n  " + text + "\n")),
               CameraModelType::kPinholeRadTan, 0, 0, 500, 500, 320, 240, {0, 0, 0, 0, 0});
}

}  // namespace
}  // namespace calibench

namespace calibench {
namespace {

// The intrinsics' covariance (`calibench intrinsics` writes it; the extrinsic's σ carries it) goes
// through every format the writer knows and back, exactly; OpenCV reads our OpenCV file.
TEST(CameraFileCovariance, RoundTripsInEveryFormat) {
  const auto dir = test::TempDir("camera_file_covariance");
  CameraModel camera;
  camera.width = 1440, camera.height = 1080;
  camera.fx = 1001.25, camera.fy = 1000.5, camera.cx = 720.125, camera.cy = 539.75;
  camera.distortion = {-0.1, 0.05, 0.0005, -0.0003};
  const int n = 8;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      camera.covariance.push_back(i == j ? 0.5 + i : 0.01 * (i + 1) * (j + 1) / 64.0);
  for (const auto& [format, name] : {std::pair{CameraFileFormat::kRosCameraInfo, "ros.yaml"},
                                     std::pair{CameraFileFormat::kOpenCv, "opencv.yaml"},
                                     std::pair{CameraFileFormat::kKalibr, "kalibr.yaml"}}) {
    SaveCameraFile(dir / name, camera, format, "cam");
    const CameraModel back = LoadCameraFile(dir / name);
    EXPECT_EQ(back.covariance, camera.covariance) << name;
    EXPECT_EQ(back.fx, camera.fx) << name;
  }
  cv::FileStorage storage((dir / "opencv.yaml").string(), cv::FileStorage::READ);
  cv::Mat covariance;
  storage["intrinsics_covariance"] >> covariance;
  ASSERT_EQ(covariance.rows, n);
  EXPECT_EQ(covariance.at<double>(2, 3), camera.covariance[2 * n + 3]);

  // A covariance of the wrong size, or not symmetric, names the file and the problem.
  Write(dir / "bad.yaml",
        "image_width: 640\nimage_height: 480\ncamera_matrix: {rows: 3, cols: 3, data: [500, 0, "
        "320, 0, 500, 240, 0, 0, 1]}\ndistortion_model: plumb_bob\ndistortion_coefficients: "
        "{rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\nintrinsics_covariance: [1, 0, 0, 1]\n");
  try {
    LoadCameraFile(dir / "bad.yaml");
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("9x9"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace calibench
