// fuzz_make_seeds OUT: writes the binary and camera seeds of tests/fuzz/corpus/ with our own
// writers (and OpenCV's for FileStorage), a few points or pixels each so that the fuzzer's
// mutations reach the parsers' every branch fast. The JSON seeds (manifests, session, result)
// come from the CLI; tests/fuzz/README.md says how. Not built by default: the corpus is committed.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "core/io/cloud_io.h"
#include "core/io/image_io.h"
#include "core/lrf_data/dataset.h"
#include "tests/bag_writers.h"

namespace calibench {
namespace {

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

LidarCloud SmallCloud(int width, int height) {
  LidarCloud cloud;
  cloud.width = width;
  cloud.height = height;
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      const Eigen::Vector3f point(1.0f + 0.1f * column, 0.05f * row - 0.2f, 0.3f);
      cloud.points.push_back(point);
      cloud.intensity.push_back(10.0f * column);
      cloud.ring.push_back(row);
      cloud.range.push_back(point.norm());
    }
  }
  return cloud;
}

void WriteClouds(const std::filesystem::path& out) {
  std::filesystem::create_directories(out / "pcd");
  std::filesystem::create_directories(out / "ply");
  std::filesystem::create_directories(out / "kitti");
  const LidarCloud cloud = SmallCloud(6, 1);
  SavePcd(out / "pcd/ascii.pcd", cloud, PcdEncoding::kAscii);
  SavePcd(out / "pcd/binary.pcd", cloud, PcdEncoding::kBinary);
  SavePcd(out / "pcd/binary_compressed.pcd", cloud, PcdEncoding::kBinaryCompressed);
  SavePcd(out / "pcd/organized.pcd", SmallCloud(3, 2), PcdEncoding::kBinary);
  // Field types and counts our writer never uses: doubles, a uint8 ring, a padded field.
  WriteText(out / "pcd/typed.pcd",
            "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z ring _ intensity\nSIZE 8 8 8 1 1 4\n"
            "TYPE F F F U U F\nCOUNT 1 1 1 1 3 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
            "POINTS 2\nDATA ascii\n1.5 0.25 -0.125 3 0 0 0 7.5\n2 nan 1 4 0 0 0 8\n");
  SavePly(out / "ply/binary_little_endian.ply", cloud);
  WriteText(out / "ply/ascii.ply",
            "ply\nformat ascii 1.0\ncomment written by hand\nelement vertex 2\n"
            "property float x\nproperty float y\nproperty float z\nproperty uchar intensity\n"
            "property ushort ring\nelement face 0\nproperty list uchar int vertex_indices\n"
            "end_header\n1 2 3 40 1\n-1 0.5 2 41 2\n");
  WriteText(out / "ply/big_endian.ply",
            std::string("ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\n"
                        "property double y\nproperty double z\nend_header\n") +
                std::string("\x3f\xf0\0\0\0\0\0\0\x40\0\0\0\0\0\0\0\x40\x08\0\0\0\0\0\0", 24));
  SaveKittiBin(out / "kitti/points.bin", cloud);
}

void WriteLrfFiles(const std::filesystem::path& out) {
  std::filesystem::create_directories(out / "scan");
  std::filesystem::create_directories(out / "depth_png");
  LaserScan scan;
  scan.angle_min = -0.5;
  scan.angle_increment = 0.05;
  scan.range_min = 0.1;
  scan.range_max = 10.0;
  for (int i = 0; i < 20; ++i) scan.ranges.push_back(1.0 + 0.01 * i);
  scan.ranges[3] = std::nan("");
  SaveLaserScanJson(out / "scan/scan.json", scan);

  DepthImage depth;
  depth.intrinsics.width = 32;
  depth.intrinsics.height = 24;
  depth.intrinsics.fx = depth.intrinsics.fy = 30.0;
  depth.intrinsics.cx = 16.0;
  depth.intrinsics.cy = 12.0;
  for (int i = 0; i < 32 * 24; ++i) depth.depth_m.push_back(i % 7 == 0 ? 0.0f : 1.0f + 0.001f * i);
  SaveDepthPng(out / "depth_png/depth.png", depth);
}

void WriteImages(const std::filesystem::path& out) {
  std::filesystem::create_directories(out / "image");
  ImageU8 image;
  image.width = 16;
  image.height = 12;
  image.channels = 3;
  image.data.resize(16 * 12 * 3);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = static_cast<uint8_t>(i * 37);
  SaveImage(out / "image/small.png", image);
  SaveImage(out / "image/small.jpg", image);
}

void WriteCameras(const std::filesystem::path& out) {
  const cv::Mat k = (cv::Mat_<double>(3, 3) << 452.5, 0, 317.7, 0, 456.8, 277.8, 0, 0, 1);
  const cv::Mat d = (cv::Mat_<double>(1, 5) << 0.12, -1.08, 1.2e-4, -4.6e-4, 2.95);
  for (const char* name : {"camera_yaml/opencv.yaml", "camera_xml/opencv.xml"}) {
    std::filesystem::create_directories((out / name).parent_path());
    cv::FileStorage storage((out / name).string(), cv::FileStorage::WRITE);
    storage << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << k
            << "distortion_coefficients" << d << "distortion_model"
            << "plumb_bob";
  }
  WriteText(out / "camera_yaml/ros_camera_info.yaml",
            "header:\n  frame_id: 'camera'\nheight: 1024\nwidth: 1280\n"
            "distortion_model: \"equidistant\"\nD: [0.02, -0.004, 0.0006, -5.0e-05]\n"
            "K: [330.5, 0.0, 640.25, 0.0, 331.5, 512.75, 0.0, 0.0, 1.0]\n---\n");
  WriteText(out / "camera_yaml/ros_calibration.yaml",
            "image_width: 1280\nimage_height: 800\ncamera_name: wide\ncamera_matrix:\n  rows: 3\n"
            "  cols: 3\n  data: [610.2, 0, 641.3, 0, 609.8, 398.7, 0, 0, 1]\n"
            "distortion_model: rational_polynomial\ndistortion_coefficients:\n  rows: 1\n"
            "  cols: 8\n  data: [0.61, -0.045, 0.0008, -0.0004, -0.0021, 0.98, 0.11, -0.0089]\n");
  WriteText(out / "camera_yaml/kalibr.yaml",
            "cam0:\n  camera_model: pinhole\n  intrinsics: [1176.93, 1177.72, 962.275, 612.725]\n"
            "  distortion_model: equidistant\n"
            "  distortion_coeffs: [-0.0540096, -0.0784275, 0.0959641, -0.0515253]\n"
            "  resolution: [1920, 1208]\n  rostopic: /cam0/image_raw\n");
}

// A tiny rig recording: a 4 x 3 organized cloud, a 16 x 12 image (raw and PNG-compressed),
// CameraInfo; in every format and compression the readers know.
std::vector<test::RecordedMessage> TinyRecording(MessageEncoding encoding) {
  CameraModel camera;
  camera.width = 16;
  camera.height = 12;
  camera.fx = camera.fy = 20.0;
  camera.cx = 8.0;
  camera.cy = 6.0;
  camera.distortion = {0.01, -0.002, 0.0, 0.0, 0.0};
  ImageU8 image;
  image.width = 16;
  image.height = 12;
  image.channels = 1;
  for (int i = 0; i < 16 * 12; ++i) image.data.push_back(static_cast<uint8_t>(i * 13));
  std::vector<uchar> png;
  cv::imencode(".png", cv::Mat(12, 16, CV_8UC1, image.data.data()), png);
  std::vector<test::RecordedMessage> messages;
  for (std::int64_t i = 0; i < 2; ++i) {
    const std::int64_t t = (10 + i) * 1'000'000'000;
    messages.push_back({"/points", "sensor_msgs/PointCloud2", t,
                        test::SerializePointCloud2(SmallCloud(4, 3), t, "lidar", encoding)});
    messages.push_back({"/cam/image_raw", "sensor_msgs/Image", t,
                        test::SerializeImage(image, "mono8", t, "cam", encoding)});
    messages.push_back({"/cam/image_raw/compressed", "sensor_msgs/CompressedImage", t,
                        test::SerializeCompressedImage("png", std::string(png.begin(), png.end()),
                                                       t, "cam", encoding)});
    messages.push_back({"/cam/camera_info", "sensor_msgs/CameraInfo", t,
                        test::SerializeCameraInfo(camera, t, "cam", encoding)});
  }
  return messages;
}

void WriteBags(const std::filesystem::path& out) {
  for (const char* folder : {"ros1_bag", "mcap", "db3", "ros_message"})
    std::filesystem::create_directories(out / folder);
  const auto ros1 = TinyRecording(MessageEncoding::kRos1);
  const auto cdr = TinyRecording(MessageEncoding::kCdr);
  for (const char* compression : {"none", "bz2", "lz4"})
    test::WriteRos1Bag(out / "ros1_bag" / (std::string(compression) + ".bag"), ros1, compression,
                       600);
  test::WriteMcap(out / "mcap/ros1_zstd.mcap", ros1, "ros1", "zstd", true, 600);
  test::WriteMcap(out / "mcap/ros2_none.mcap", cdr, "ros2", "", true, 600);
  test::WriteMcap(out / "mcap/ros2_lz4_no_summary.mcap", cdr, "ros2", "lz4", false, 600);
  test::WriteDb3(out / "db3/ros2.db3", cdr);
  // One message per type and serialization, prefixed by the harness's selector byte.
  static const char* const types[] = {"sensor_msgs/PointCloud2", "sensor_msgs/Image",
                                      "sensor_msgs/CompressedImage", "sensor_msgs/CameraInfo"};
  for (const auto* messages : {&ros1, &cdr})
    for (int type = 0; type < 4; ++type)
      for (const test::RecordedMessage& message : *messages)
        if (message.type == types[type]) {
          const int selector = type | (messages == &cdr ? 4 : 0);
          std::vector<std::uint8_t> bytes = {static_cast<std::uint8_t>(selector)};
          bytes.insert(bytes.end(), message.data.begin(), message.data.end());
          std::ofstream(out / "ros_message" / (std::to_string(selector) + ".msg"), std::ios::binary)
              .write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
          break;
        }
}

}  // namespace
}  // namespace calibench

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds OUT\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  calibench::WriteClouds(out);
  calibench::WriteLrfFiles(out);
  calibench::WriteImages(out);
  calibench::WriteCameras(out);
  calibench::WriteBags(out);
  return 0;
}
