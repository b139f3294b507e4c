// sensor_msgs decoding in both serializations, every encoding Calibench promises, and the
// refusals of malformed messages.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/recording/ros_messages.h"
#include "tests/bag_writers.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

LidarCloud MessageTestCloud(int width, int height) {
  LidarCloud cloud;
  for (int row = 0; row < height; ++row)
    for (int column = 0; column < width; ++column) {
      cloud.points.emplace_back(1.5f + 0.01f * column, -0.25f * row, 0.125f * (column - row));
      cloud.intensity.push_back(static_cast<float>(row * 10 + column));
      cloud.ring.push_back(row);
    }
  cloud.width = width;
  cloud.height = height;
  return cloud;
}

ImageU8 GradientImage(int width, int height, int channels) {
  ImageU8 image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        image.data.push_back(static_cast<std::uint8_t>((x * 7 + y * 3 + c * 50) % 256));
  return image;
}

TEST(RosMessages, PointCloud2InEveryByteOrderAndSerialization) {
  const LidarCloud cloud = MessageTestCloud(12, 4);
  for (const auto& [encoding, big_endian] :
       {std::pair{MessageEncoding::kRos1, false}, std::pair{MessageEncoding::kCdr, false},
        std::pair{MessageEncoding::kCdr, true}}) {
    const auto bytes =
        test::SerializePointCloud2(cloud, 1'234'567'890'123, "lidar", encoding, big_endian);
    const PointCloud2Message message = DecodePointCloud2(bytes, encoding);
    EXPECT_EQ(message.header.stamp_ns, 1'234'567'890'123);
    EXPECT_EQ(message.header.frame_id, "lidar");
    EXPECT_EQ(message.cloud.points, cloud.points);
    EXPECT_EQ(message.cloud.intensity, cloud.intensity);
    EXPECT_EQ(message.cloud.ring, cloud.ring);
    EXPECT_TRUE(message.cloud.IsOrganized());
    EXPECT_EQ(message.fields,
              "x:FLOAT32@0 y:FLOAT32@4 z:FLOAT32@8 intensity:FLOAT32@16 "
              "ring:UINT16@20");
  }
}

// A swept scanner's driver that knows its mirror stores each return's ray origin as PCL's
// PointWithViewpoint does (vp_x, vp_y, vp_z): read into the cloud, in every serialization.
TEST(RosMessages, PointCloud2ViewpointsAreEachReturnsRayOrigin) {
  LidarCloud cloud = MessageTestCloud(6, 2);
  for (size_t i = 0; i < cloud.size(); ++i)
    cloud.viewpoint.emplace_back(0.1f, 0.01f * static_cast<float>(i), -0.05f);
  for (const auto& [encoding, big_endian] :
       {std::pair{MessageEncoding::kRos1, false}, std::pair{MessageEncoding::kCdr, true}}) {
    const PointCloud2Message message = DecodePointCloud2(
        test::SerializePointCloud2(cloud, 1, "lidar", encoding, big_endian), encoding);
    EXPECT_EQ(message.cloud.points, cloud.points);
    EXPECT_EQ(message.cloud.viewpoint, cloud.viewpoint);
  }
  cloud.viewpoint.clear();
  EXPECT_FALSE(
      DecodePointCloud2(test::SerializePointCloud2(cloud, 1, "lidar", MessageEncoding::kRos1),
                        MessageEncoding::kRos1)
          .cloud.HasViewpoint());
}

TEST(RosMessages, NonFinitePointsAreDroppedAndTheGridWithThem) {
  LidarCloud cloud = MessageTestCloud(5, 2);
  cloud.points[3].x() = std::numeric_limits<float>::quiet_NaN();
  const auto bytes = test::SerializePointCloud2(cloud, 1, "lidar", MessageEncoding::kRos1);
  const PointCloud2Message message = DecodePointCloud2(bytes, MessageEncoding::kRos1);
  EXPECT_EQ(message.cloud.size(), 9u);
  EXPECT_EQ(message.cloud.height, 1);
  EXPECT_EQ(message.declared_points, 10);
}

TEST(RosMessages, MalformedCloudsAreRefusedWithTheReason) {
  const LidarCloud cloud = MessageTestCloud(6, 1);
  auto bytes = test::SerializePointCloud2(cloud, 1, "lidar", MessageEncoding::kRos1);
  bytes.resize(bytes.size() - 40);  // cut into the point data
  EXPECT_THROW(
      {
        try {
          DecodePointCloud2(bytes, MessageEncoding::kRos1);
        } catch (const std::invalid_argument& error) {
          EXPECT_NE(std::string(error.what()).find("PointCloud2: the message ends inside"),
                    std::string::npos)
              << error.what();
          throw;
        }
      },
      std::invalid_argument);
  LoadLimits limits;
  limits.max_cloud_points = 5;
  const auto whole = test::SerializePointCloud2(cloud, 1, "lidar", MessageEncoding::kRos1);
  try {
    DecodePointCloud2(whole, MessageEncoding::kRos1, limits);
    ADD_FAILURE() << "6 points passed a limit of 5";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("6 points is over the limit of 5"), std::string::npos)
        << error.what();
  }
}

// Issue 46 item 3: livox_ros_driver(2)/CustomMsg in both serializations. The sizes follow from
// the definition alone: ROS 1 packs a point in 19 bytes, CDR aligns each to 20.
// A multi-laser Livox (an Avia's 6 lines, a Mid-360's 4) interleaves its lasers' returns; each
// laser's own order is its beam's path. Both the CustomMsg and a Livox driver's PointCloud2 with
// its "line" field come back laser by laser, each in firing order, and without rings (a laser of
// a prism head follows the rosette, not a cone).
TEST(RosMessages, LivoxLinesAreStoredLaserByLaserNotAsRings) {
  LidarCloud cloud;
  for (int i = 0; i < 12; ++i) {
    cloud.points.emplace_back(2.f + 0.01f * i, 0.1f * (i % 3), 0.2f);
    cloud.intensity.push_back(static_cast<float>(i));
    cloud.ring.push_back(i % 3);  // the laser, interleaved as the driver sends them
  }
  cloud.width = static_cast<int>(cloud.size());
  const std::vector<int> expected_order = {0, 3, 6, 9, 1, 4, 7, 10, 2, 5, 8, 11};
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    SCOPED_TRACE(encoding == MessageEncoding::kRos1 ? "ROS 1" : "CDR");
    const LivoxCustomMessage custom = DecodeLivoxCustomMsg(
        test::SerializeLivoxCustomMsg(cloud, 1'000, "livox_frame", encoding), encoding);
    const PointCloud2Message pc2 = DecodePointCloud2(
        test::SerializePointCloud2(cloud, 1'000, "livox_frame", encoding, false, "line"), encoding);
    for (const LidarCloud* decoded : {&custom.cloud, &pc2.cloud}) {
      EXPECT_FALSE(decoded->HasRing());
      ASSERT_EQ(decoded->size(), cloud.size());
      for (std::size_t k = 0; k < expected_order.size(); ++k) {
        EXPECT_EQ(decoded->points[k], cloud.points[expected_order[k]]) << k;
        EXPECT_EQ(decoded->intensity[k], cloud.intensity[expected_order[k]]) << k;
      }
    }
    for (std::size_t k = 0; k < expected_order.size(); ++k)
      EXPECT_EQ(custom.offset_time_ns[k], expected_order[k] * 10'000u) << k;
    // A ring field by its own name stays a ring.
    const PointCloud2Message rings =
        DecodePointCloud2(test::SerializePointCloud2(cloud, 1'000, "velodyne", encoding), encoding);
    EXPECT_EQ(rings.cloud.ring, cloud.ring);
  }
}

TEST(RosMessages, LivoxCustomMsgInBothSerializations) {
  LidarCloud cloud = MessageTestCloud(5, 1);
  cloud.ring.clear();
  cloud.points.emplace_back(0.f, 0.f, 0.f);  // no return
  cloud.intensity.push_back(0.f);
  cloud.points.emplace_back(2.f, 0.5f, 0.25f);  // tagged high-confidence noise
  cloud.intensity.push_back(40.f);
  cloud.width = static_cast<int>(cloud.size());
  const std::vector<std::uint32_t> offsets = {0, 10, 20, 30, 40, 50, 60};
  const std::vector<std::uint8_t> tags = {0, 0x10, 0x02, 0, 0, 0, 0x01};
  for (MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
    SCOPED_TRACE(encoding == MessageEncoding::kRos1 ? "ROS 1" : "CDR");
    const auto data = test::SerializeLivoxCustomMsg(cloud, 1'700'000'000'250'000'000, "livox_frame",
                                                    encoding, offsets, tags);
    const bool cdr = encoding == MessageEncoding::kCdr;
    // Header (ROS 1: seq + stamp + "livox_frame"; CDR: encapsulation + stamp + terminated
    // string, which ends 8-aligned for timebase), timebase 8, point_num 4, lidar_id + rsvd 4,
    // the sequence's length 4.
    const std::size_t header = cdr ? 4 + 8 + 4 + 12 : 4 + 8 + 4 + 11;
    EXPECT_EQ(data.size(), header + 8 + 4 + 4 + 4 + (cdr ? 20 * 6 + 19 : 19 * 7));
    const LivoxCustomMessage message = DecodeLivoxCustomMsg(data, encoding);
    EXPECT_EQ(message.header.stamp_ns, 1'700'000'000'250'000'000);
    EXPECT_EQ(message.header.frame_id, "livox_frame");
    EXPECT_EQ(message.timebase_ns, 1'700'000'000'250'000'000u);
    EXPECT_EQ(message.lidar_id, 3);
    EXPECT_EQ(message.declared_points, 7);
    EXPECT_EQ(message.noise_dropped, 1);
    ASSERT_EQ(message.cloud.size(), 5u);  // the zero return and the noise dropped
    EXPECT_FALSE(message.cloud.HasRing());
    for (int i = 0; i < 5; ++i) {
      EXPECT_EQ(message.cloud.points[i], cloud.points[i]);
      EXPECT_EQ(message.cloud.intensity[i], cloud.intensity[i]);
      EXPECT_EQ(message.offset_time_ns[i], offsets[i]);
    }
    EXPECT_EQ(DecodeCloudMessage(data, true, encoding).cloud.size(), 5u);
    // Refusals: cut short, and more points than the limit allows.
    const std::vector<std::uint8_t> cut(data.begin(), data.end() - 10);
    EXPECT_THROW(DecodeLivoxCustomMsg(cut, encoding), std::invalid_argument);
    LoadLimits small;
    small.max_cloud_points = 4;
    try {
      DecodeLivoxCustomMsg(data, encoding, small);
      ADD_FAILURE() << "no refusal";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("7 points, more than the 4"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_TRUE(IsCloudType("livox_ros_driver2/CustomMsg"));
  EXPECT_TRUE(IsCloudType("livox_ros_driver/CustomMsg"));
  EXPECT_FALSE(IsCloudType("livox_ros_driver2/CustomPoint"));
}

TEST(RosMessages, ImageEncodingsGiveTheSamePixels) {
  const ImageU8 bgr = GradientImage(16, 10, 3);
  const ImageMessage direct = DecodeImage(
      test::SerializeImage(bgr, "bgr8", 5, "cam", MessageEncoding::kCdr), MessageEncoding::kCdr);
  EXPECT_EQ(direct.image.data, bgr.data);
  ImageU8 rgb = bgr;
  for (std::size_t i = 0; i < rgb.data.size(); i += 3) std::swap(rgb.data[i], rgb.data[i + 2]);
  const ImageMessage from_rgb = DecodeImage(
      test::SerializeImage(rgb, "rgb8", 5, "cam", MessageEncoding::kRos1), MessageEncoding::kRos1);
  EXPECT_EQ(from_rgb.image.data, bgr.data);
  const ImageU8 mono = GradientImage(16, 10, 1);
  const ImageMessage grey =
      DecodeImage(test::SerializeImage(mono, "mono8", 5, "cam", MessageEncoding::kRos1),
                  MessageEncoding::kRos1);
  EXPECT_EQ(grey.image.channels, 1);
  EXPECT_EQ(grey.image.data, mono.data);
}

// A Bayer mosaic made from a colour image debayers back to it (in its flat interior); the four
// patterns use cv_bridge's names.
TEST(RosMessages, BayerPatternsDebayerToTheRightColours) {
  cv::Mat colour(32, 32, CV_8UC3, cv::Scalar(200, 100, 30));  // B G R
  for (const auto& [name, offset] :
       {std::pair{"bayer_rggb8", cv::Point(0, 0)}, std::pair{"bayer_bggr8", cv::Point(1, 1)},
        std::pair{"bayer_gbrg8", cv::Point(0, 1)}, std::pair{"bayer_grbg8", cv::Point(1, 0)}}) {
    ImageU8 mosaic;
    mosaic.width = mosaic.height = 32;
    mosaic.channels = 1;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        // In RGGB the red sample sits at (even x, even y); other patterns shift it.
        const int px = (x + offset.x) % 2, py = (y + offset.y) % 2;
        const int channel = px == 0 && py == 0 ? 2 : px == 1 && py == 1 ? 0 : 1;
        mosaic.data.push_back(colour.at<cv::Vec3b>(y, x)[channel]);
      }
    const ImageMessage decoded =
        DecodeImage(test::SerializeImage(mosaic, name, 1, "cam", MessageEncoding::kRos1),
                    MessageEncoding::kRos1);
    ASSERT_EQ(decoded.image.channels, 3) << name;
    const std::uint8_t* centre = decoded.image.Row(16) + 16 * 3;
    EXPECT_NEAR(centre[0], 200, 2) << name;
    EXPECT_NEAR(centre[1], 100, 2) << name;
    EXPECT_NEAR(centre[2], 30, 2) << name;
  }
}

TEST(RosMessages, Mono16IsScaledByItsLargestValue) {
  ImageU8 sixteen;  // 12-bit data in 16-bit words, little-endian
  sixteen.width = 4;
  sixteen.height = 1;
  sixteen.channels = 2;
  for (const std::uint16_t value : {0, 1024, 2048, 4095}) {
    sixteen.data.push_back(value & 0xff);
    sixteen.data.push_back(value >> 8);
  }
  const ImageMessage decoded =
      DecodeImage(test::SerializeImage(sixteen, "mono16", 1, "cam", MessageEncoding::kRos1),
                  MessageEncoding::kRos1);
  const std::vector<std::uint8_t> expected = {0, 64, 128, 255};
  EXPECT_EQ(decoded.image.data, expected);
}

TEST(RosMessages, CompressedPngAndJpeg) {
  cv::Mat colour(24, 40, CV_8UC3);
  cv::randu(colour, 0, 255);
  std::vector<std::uint8_t> png;
  cv::imencode(".png", colour, png);
  const auto message = test::SerializeCompressedImage("bgr8; png compressed bgr8",
                                                      std::string(png.begin(), png.end()), 1, "cam",
                                                      MessageEncoding::kCdr);
  const ImageMessage decoded = DecodeCompressedImage(message, MessageEncoding::kCdr);
  ASSERT_EQ(decoded.image.width, 40);
  EXPECT_EQ(0, std::memcmp(decoded.image.data.data(), colour.data, decoded.image.data.size()));
  const auto text = test::SerializeCompressedImage("jpeg", "not an image at all", 1, "cam",
                                                   MessageEncoding::kCdr);
  EXPECT_THROW(DecodeCompressedImage(text, MessageEncoding::kCdr), std::invalid_argument);
}

TEST(RosMessages, CameraInfoModels) {
  CameraModel camera;
  camera.width = 1440;
  camera.height = 1080;
  camera.fx = 1001.25;
  camera.fy = 999.5;
  camera.cx = 719.75;
  camera.cy = 541.125;
  for (const auto& [type, distortion, name] :
       {std::tuple{CameraModelType::kPinholeRadTan,
                   std::vector<double>{-0.1, 0.05, 1e-4, -2e-4, 0.01}, "plumb_bob"},
        std::tuple{CameraModelType::kPinholeRadTan,
                   std::vector<double>{-0.1, 0.05, 1e-4, -2e-4, 0.01, 0.2, -0.03, 0.004},
                   "rational_polynomial"},
        std::tuple{CameraModelType::kKannalaBrandt, std::vector<double>{0.05, -0.01, 0.002, -1e-4},
                   "equidistant"}}) {
    camera.type = type;
    camera.distortion = distortion;
    for (const MessageEncoding encoding : {MessageEncoding::kRos1, MessageEncoding::kCdr}) {
      const CameraInfoMessage info =
          DecodeCameraInfo(test::SerializeCameraInfo(camera, 1, "cam", encoding), encoding);
      EXPECT_EQ(info.distortion_model, name);
      EXPECT_EQ(info.camera.type, type);
      EXPECT_EQ(info.camera.distortion, distortion);
      EXPECT_EQ(info.camera.fx, camera.fx);
      EXPECT_EQ(info.camera.cy, camera.cy);
    }
  }
  camera.fx = camera.fy = camera.cx = camera.cy = 0;  // a driver without a calibration
  camera.type = CameraModelType::kPinholeRadTan;
  camera.distortion = {0, 0, 0, 0, 0};
  try {
    DecodeCameraInfo(test::SerializeCameraInfo(camera, 1, "cam", MessageEncoding::kRos1),
                     MessageEncoding::kRos1);
    ADD_FAILURE() << "a K without focal length was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("publishes no calibration"), std::string::npos);
  }
}

}  // namespace
}  // namespace calibench
