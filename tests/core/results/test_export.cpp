// Exports (core/results/export.h): every format written and read back gives the same transform
// (<= 1e-12), in both camera-frame conventions and both parent/child orders; the link variant is
// the optical one composed with REP 103's fixed rotation; OpenCV reads its YAML; known ROS values
// come out (a forward-looking camera's optical frame is rpy (-90, 0, -90) degrees in the LiDAR's).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>

#include "core/results/export.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

Pose SomeCalibration() {
  Pose cam_from_lidar = DefaultCamFromLidar();
  cam_from_lidar.linear() =
      cam_from_lidar.linear() *
      Eigen::AngleAxisd(0.0123, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  cam_from_lidar.translation() += Vec3(0.0123456789, -0.0311, 0.207);
  return cam_from_lidar;
}

fs::path WriteExport(const fs::path& dir, ExportFormat format, const Pose& cam_from_lidar,
                     const ExportFrames& frames, const std::string& tag) {
  const fs::path path = dir / (tag + "_" + DefaultExportFileName(format));
  std::ofstream(path) << ExportCalibration(format, cam_from_lidar, frames, "result.json").text;
  return path;
}

TEST(Export, EveryFormatReadsBackToTheSameTransform) {
  const fs::path dir = test::TempDir("export_round_trip");
  const Pose cam_from_lidar = SomeCalibration();
  for (const ExportFormat format : AllExportFormats()) {
    for (const CameraFrame camera_frame : {CameraFrame::kOptical, CameraFrame::kLink}) {
      for (const bool swapped : {false, true}) {
        ExportFrames frames;
        frames.lidar = "velodyne";
        frames.camera = camera_frame == CameraFrame::kLink ? "camera_link" : "camera_optical_frame";
        frames.camera_is_parent = swapped;
        frames.camera_frame = camera_frame;
        const std::string tag = CameraFrameName(camera_frame) + (swapped ? "_swapped" : "");
        const fs::path path = WriteExport(dir, format, cam_from_lidar, frames, tag);
        SCOPED_TRACE(path.string());
        const ImportedTransform imported = ReadExportedTransform(path);
        ASSERT_TRUE(imported.format.has_value());
        EXPECT_EQ(*imported.format, format);
        EXPECT_EQ(imported.parent, frames.parent());
        EXPECT_EQ(imported.child, frames.child());
        EXPECT_TRUE(test::MatrixNear(imported.parent_from_child.matrix(),
                                     ParentFromChild(cam_from_lidar, frames).matrix(), 1e-12));
        EXPECT_TRUE(test::MatrixNear(CamFromLidarOf(imported.parent_from_child, frames).matrix(),
                                     cam_from_lidar.matrix(), 1e-12));
      }
    }
  }
}

TEST(Export, TheLinkFrameIsTheOpticalFrameTurnedByRep103) {
  const fs::path dir = test::TempDir("export_link");
  // REP 103: optical z (forward) is link x, optical x (right) is link -y, optical y (down) -z.
  EXPECT_TRUE(test::MatrixNear(LinkFromOptical() * Vec3::UnitZ(), Vec3::UnitX(), 0.0));
  EXPECT_TRUE(test::MatrixNear(LinkFromOptical() * Vec3::UnitX(), Vec3(0, -1, 0), 0.0));
  EXPECT_TRUE(test::MatrixNear(LinkFromOptical() * Vec3::UnitY(), Vec3(0, 0, -1), 0.0));
  const Pose cam_from_lidar = SomeCalibration();
  Pose optical_from_link = Pose::Identity();
  optical_from_link.linear() = LinkFromOptical().transpose();
  for (const ExportFormat format : AllExportFormats()) {
    ExportFrames optical, link;
    link.camera_frame = CameraFrame::kLink;
    const Pose lidar_from_optical =
        ReadExportedTransform(WriteExport(dir, format, cam_from_lidar, optical, "optical"))
            .parent_from_child;
    const Pose lidar_from_link =
        ReadExportedTransform(WriteExport(dir, format, cam_from_lidar, link, "link"))
            .parent_from_child;
    EXPECT_TRUE(test::MatrixNear(lidar_from_link.matrix(),
                                 (lidar_from_optical * optical_from_link).matrix(), 1e-12))
        << ExportFormatName(format);
  }
}

TEST(Export, AForwardCameraHasRosWellKnownAngles) {
  // A camera looking along the LiDAR's x, 10 cm below it. ROS's optical
  // joints for such a camera read rpy = (-pi/2, 0, -pi/2); its link frame is the LiDAR's axes.
  Pose cam_from_lidar = Pose::Identity();
  cam_from_lidar.linear() = LinkFromOptical().transpose();
  cam_from_lidar.translation() = Vec3(0.0, -0.1, 0.0);
  ExportFrames frames;
  const Vec3 optical = RollPitchYaw(ParentFromChild(cam_from_lidar, frames).rotation());
  EXPECT_TRUE(test::MatrixNear(optical, Vec3(-M_PI / 2, 0, -M_PI / 2), 1e-9)) << optical;
  frames.camera_frame = CameraFrame::kLink;
  EXPECT_TRUE(
      test::MatrixNear(ParentFromChild(cam_from_lidar, frames).rotation(), Mat3::Identity(), 1e-9));
  // Roll-pitch-yaw round trips, at gimbal lock too.
  for (const Vec3& rpy :
       {Vec3(0.3, -1.2, 2.9), Vec3(-2.0, M_PI / 2, 0.0), Vec3(0.7, -M_PI / 2, 0.0)}) {
    const Mat3 r = RotationFromRollPitchYaw(rpy.x(), rpy.y(), rpy.z());
    const Vec3 back = RollPitchYaw(r);
    EXPECT_TRUE(test::MatrixNear(RotationFromRollPitchYaw(back.x(), back.y(), back.z()), r, 1e-12));
  }
}

TEST(Export, OpenCvReadsItsYamlAndEveryFileSaysTheDirection) {
  const fs::path dir = test::TempDir("export_opencv");
  const Pose cam_from_lidar = SomeCalibration();
  ExportFrames frames;
  const fs::path path = WriteExport(dir, ExportFormat::kOpenCvYaml, cam_from_lidar, frames, "cv");
  cv::FileStorage storage(path.string(), cv::FileStorage::READ);
  ASSERT_TRUE(storage.isOpened());
  cv::Mat matrix;
  storage["parent_from_child"] >> matrix;
  ASSERT_EQ(matrix.rows, 4);
  const Mat4 expected = ParentFromChild(cam_from_lidar, frames).matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(matrix.at<double>(r, c), expected(r, c));
  EXPECT_EQ(static_cast<std::string>(storage["parent_frame"]), "lidar");
  for (const ExportFormat format : AllExportFormats()) {
    const std::string text = ExportCalibration(format, cam_from_lidar, frames, "r.json").text;
    EXPECT_NE(text.find("x_in_lidar = lidar_from_camera * x_in_camera"), std::string::npos)
        << ExportFormatName(format);
    EXPECT_NE(text.find("optical (z forward, x right, y down"), std::string::npos);
  }
  const ExportedCalibration ros2 =
      ExportCalibration(ExportFormat::kRos2Tf, cam_from_lidar, frames, "r.json");
  EXPECT_EQ(ros2.command.rfind("ros2 run tf2_ros static_transform_publisher --x ", 0), 0u);
  EXPECT_NE(ros2.command.find("--frame-id lidar --child-frame-id camera"), std::string::npos);
}

TEST(Export, ForeignFilesAndBrokenOnesAreReadOrRefusedByName) {
  const fs::path dir = test::TempDir("export_foreign");
  // A hand-written ROS 1 launch file in the yaw-pitch-roll form.
  std::ofstream(dir / "old.launch")
      << "<launch><node pkg=\"tf\" type=\"static_transform_publisher\" name=\"x\" "
         "args=\"0.1 0.2 0.3 1.5707963267948966 0 0 base_link camera_link 100\"/></launch>";
  const ImportedTransform old = ReadExportedTransform(dir / "old.launch");
  EXPECT_EQ(old.parent, "base_link");
  EXPECT_EQ(old.child, "camera_link");
  EXPECT_TRUE(
      test::MatrixNear(old.parent_from_child.rotation() * Vec3::UnitX(), Vec3::UnitY(), 1e-12));
  EXPECT_TRUE(test::MatrixNear(old.parent_from_child.translation(), Vec3(0.1, 0.2, 0.3), 0.0));
  std::ofstream(dir / "bad.txt") << "1 0 0 0\n0 1 0 0\n0 0 2 0\n0 0 0 1\n";
  try {
    ReadExportedTransform(dir / "bad.txt");
    FAIL() << "a scaled matrix is not a calibration";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a rigid transform"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "none.yaml") << "foo: 1\n";
  EXPECT_THROW(ReadExportedTransform(dir / "none.yaml"), IoError);
}

}  // namespace
}  // namespace calibench
