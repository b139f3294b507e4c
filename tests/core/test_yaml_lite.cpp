// The YAML subset reader on the shapes ROS, Kalibr and OpenCV files take, and on broken text.
#include <gtest/gtest.h>

#include <cmath>

#include "core/io/yaml_lite.h"

namespace calibench {
namespace {

YamlNode Parse(const std::string& text) {
  std::string why;
  const std::optional<YamlNode> node = ParseYamlLite(text, &why);
  EXPECT_TRUE(node) << why;
  return node ? *node : YamlNode{};
}

std::vector<double> Doubles(const YamlNode& node) {
  std::vector<double> out;
  for (const YamlNode& item : node.items) out.push_back(item.AsDouble().value_or(NAN));
  return out;
}

TEST(YamlLiteTest, RosCameraCalibrationFile) {
  const YamlNode root = Parse(
      "image_width: 964\n"
      "camera_name: narrow_stereo\n"
      "camera_matrix:\n"
      "  rows: 3\n"
      "  cols: 3\n"
      "  data: [484.130454, 0.000000, 457.177461, 0.000000, 484.452449, 364.861413, 0, 0, 1]\n"
      "distortion_model: plumb_bob\r\n"
      "distortion_coefficients:\n"
      "  rows: 1\n"
      "  cols: 5\n"
      "  data: [-0.199619, 0.068964, 0.003371, 0.000296, 0.000000]\n");
  ASSERT_EQ(root.kind, YamlNode::Kind::kMap);
  EXPECT_EQ(root.entries.size(), 5u);
  EXPECT_EQ(root.Find("image_width")->AsDouble(), 964.0);
  EXPECT_EQ(root.Find("camera_name")->scalar, "narrow_stereo");
  EXPECT_EQ(root.Find("distortion_model")->scalar, "plumb_bob");
  const YamlNode* k = root.Find("camera_matrix");
  ASSERT_TRUE(k);
  EXPECT_EQ(k->line, 4);  // where its first entry is
  EXPECT_EQ(k->Find("rows")->AsDouble(), 3.0);
  EXPECT_EQ(Doubles(*k->Find("data")),
            (std::vector<double>{484.130454, 0, 457.177461, 0, 484.452449, 364.861413, 0, 0, 1}));
  EXPECT_EQ(Doubles(*root.Find("distortion_coefficients")->Find("data")),
            (std::vector<double>{-0.199619, 0.068964, 0.003371, 0.000296, 0}));
  EXPECT_EQ(root.Find("missing"), nullptr);
  EXPECT_EQ(k->Find("data")->Find("rows"), nullptr);
}

TEST(YamlLiteTest, KalibrCamchainWithSequencesAtKeyIndentAndComments) {
  const YamlNode root = Parse(
      "# Kalibr output\n"
      "cam0:\n"
      "  T_cam_imu:\n"
      "  - [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975]\n"
      "  - [0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768]\n"
      "  cam_overlaps: []   # none\n"
      "  camera_model: pinhole\n"
      "  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359,\n"
      "      1.76187114e-05]\n"
      "  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
      "  resolution: [752, 480]\n"
      "  rostopic: /cam0/image_raw\n"
      "\n"
      "cam1:\n"
      "  camera_model: 'pinhole'\n"
      "  rostopic: \"/cam1/image#raw\"  # the '#' inside quotes is text\n");
  const YamlNode* cam0 = root.Find("cam0");
  ASSERT_TRUE(cam0);
  const YamlNode* t = cam0->Find("T_cam_imu");
  ASSERT_TRUE(t);
  ASSERT_EQ(t->kind, YamlNode::Kind::kSequence);
  ASSERT_EQ(t->items.size(), 2u);
  EXPECT_EQ(t->items[1].items[3].AsDouble(), -0.064676986768);
  EXPECT_EQ(cam0->Find("cam_overlaps")->kind, YamlNode::Kind::kSequence);
  EXPECT_TRUE(cam0->Find("cam_overlaps")->items.empty());
  EXPECT_EQ(Doubles(*cam0->Find("distortion_coeffs")),
            (std::vector<double>{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}));
  EXPECT_EQ(cam0->Find("rostopic")->scalar, "/cam0/image_raw");
  const YamlNode* cam1 = root.Find("cam1");
  ASSERT_TRUE(cam1);
  EXPECT_EQ(cam1->Find("camera_model")->scalar, "pinhole");
  EXPECT_TRUE(cam1->Find("camera_model")->quoted);
  EXPECT_EQ(cam1->Find("rostopic")->scalar, "/cam1/image#raw");
}

TEST(YamlLiteTest, OpenCvStyleHeaderTagsAndMultiLineFlow) {
  const YamlNode root = Parse(
      "%YAML:1.0\n"
      "---\n"
      "calibration_time: \"Wed 08 Dec 2021 05:13:09 PM MSK\"\n"
      "camera_matrix: !!opencv-matrix\n"
      "   rows: 3\n"
      "   cols: 3\n"
      "   dt: d\n"
      "   data: [ 4.5251072219637672e+02, 0., 3.1770297317353277e+02, 0.,\n"
      "       4.5676707935146891e+02, 2.7775155919135995e+02, 0., 0., 1. ]\n"
      "info: \"The camera: it's fine\"\n");
  EXPECT_EQ(root.Find("calibration_time")->scalar, "Wed 08 Dec 2021 05:13:09 PM MSK");
  const std::vector<double> k = Doubles(*root.Find("camera_matrix")->Find("data"));
  ASSERT_EQ(k.size(), 9u);
  EXPECT_EQ(k[0], 4.5251072219637672e+02);
  EXPECT_EQ(k[5], 2.7775155919135995e+02);
  EXPECT_EQ(root.Find("camera_matrix")->Find("dt")->scalar, "d");
  EXPECT_EQ(root.Find("info")->scalar, "The camera: it's fine");
}

TEST(YamlLiteTest, SequencesOfMapsNestedFlowQuotesAndNulls) {
  const YamlNode root = Parse(
      "cameras:\n"
      "  - name: left\n"
      "    size: {w: 640, h: 480}\n"
      "  - name: 'it''s right'\n"
      "    note: don't split\n"
      "  -\n"
      "    - [1, [2, 3], \"a, b\"]\n"
      "empty:\n"
      "tilde: ~\n"
      "escaped: \"tab\\tquote\\\" end\"\n"
      "long: a plain scalar\n"
      "  continued here\n"
      "literal: |\n"
      "  line one\n"
      "    indented\n"
      "top: &anchor value\n");
  const YamlNode* cameras = root.Find("cameras");
  ASSERT_TRUE(cameras);
  ASSERT_EQ(cameras->items.size(), 3u);
  EXPECT_EQ(cameras->items[0].Find("name")->scalar, "left");
  EXPECT_EQ(cameras->items[0].Find("size")->Find("h")->AsDouble(), 480.0);
  EXPECT_EQ(cameras->items[1].Find("name")->scalar, "it's right");
  EXPECT_EQ(cameras->items[1].Find("note")->scalar, "don't split");
  const YamlNode& nested = cameras->items[2].items[0];
  ASSERT_EQ(nested.items.size(), 3u);
  EXPECT_EQ(nested.items[1].items[1].AsDouble(), 3.0);
  EXPECT_EQ(nested.items[2].scalar, "a, b");
  EXPECT_EQ(root.Find("empty")->kind, YamlNode::Kind::kNull);
  EXPECT_EQ(root.Find("tilde")->kind, YamlNode::Kind::kNull);
  EXPECT_EQ(root.Find("escaped")->scalar, "tab\tquote\" end");
  EXPECT_EQ(root.Find("long")->scalar, "a plain scalar continued here");
  EXPECT_EQ(root.Find("literal")->scalar, "line one\n  indented\n");
  EXPECT_EQ(root.Find("top")->scalar, "value");
}

TEST(YamlLiteTest, EmptyDocumentIsNull) {
  EXPECT_EQ(Parse("").kind, YamlNode::Kind::kNull);
  EXPECT_EQ(Parse("# only a comment\n\n").kind, YamlNode::Kind::kNull);
}

TEST(YamlLiteTest, NumbersAreReadExactlyAndStrictly) {
  const auto number = [](const std::string& text) {
    YamlNode node;
    node.kind = YamlNode::Kind::kScalar;
    node.scalar = text;
    return node.AsDouble();
  };
  EXPECT_EQ(number("1"), 1.0);
  EXPECT_EQ(number("-2.5e-3"), -2.5e-3);
  EXPECT_EQ(number("+3"), 3.0);
  EXPECT_EQ(number("0."), 0.0);
  EXPECT_EQ(number(".5"), 0.5);
  EXPECT_EQ(number("1.76187114e-05"), 1.76187114e-05);
  EXPECT_EQ(number("0.1213692561870787"), 0.1213692561870787);
  EXPECT_EQ(number(".inf"), INFINITY);
  EXPECT_EQ(number("-.inf"), -INFINITY);
  EXPECT_TRUE(std::isnan(number(".nan").value_or(0)));
  for (const char* bad : {"", "1.0abc", "--1", "+-1", "abc", "1,5", "0x10", " 1"}) {
    EXPECT_FALSE(number(bad)) << bad;
  }
  EXPECT_FALSE(YamlNode{}.AsDouble());
}

TEST(YamlLiteTest, BrokenTextIsRejectedWithTheLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"a: 1\n  b: 2\n", "line 2"},
      {"a: 1\nb: [1, 2\n", "line 2: unclosed bracket"},
      {"a: \"open\nb: 2\n", "unclosed quote"},
      {"a: 1\na: 2\n", "line 2: duplicate key 'a'"},
      {"a:\n\tb: 1\n", "line 2: tab"},
      {"a: *ref\n", "aliases"},
      {"a: [1, 2] x\n", "unexpected text"},
      {"a: [1,, 2]\n", "unexpected ','"},
      {"a: {b: 1, b: 2}\n", "duplicate key 'b'"},
      {"a: 1\n- b\n", "line 2"},
      {std::string("a: 1\0\x01\x02", 7), "binary"},
      {std::string(200, '[') + std::string(200, ']'), "nesting"},
  };
  for (const auto& [text, expected] : cases) {
    std::string why;
    EXPECT_FALSE(ParseYamlLite(text, &why)) << text;
    EXPECT_NE(why.find(expected), std::string::npos) << "text: " << text << "\nwhy: " << why;
  }
}

}  // namespace
}  // namespace calibench
