// `calibench export` and `evaluate --reference` through the real executable: a calibrated
// simulation exported in every format, each file compared back with the result (a difference of
// 0.00 mm / 0.000 deg), and a session exported like its result.
#include <gtest/gtest.h>
#include <unistd.h>

#include "core/io/dataset.h"
#include "core/results/export.h"
#include "core/results/result_file.h"
#include "core/session/session.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

class ExportCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(test::TempDir("export_cli_" + std::to_string(getpid())));
    SimOptions sim = SimPreset("default");
    sim.num_pairs = 5;
    sim.seed = 21;
    sim.lidar = LidarModel::kVlp16;
    SimulateDataset(sim, *dir_ / "data");
    std::string output;
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                   (*dir_ / "data").string() + " --out " + Result().string(),
                               &output),
              0)
        << output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path Result() { return *dir_ / "result.json"; }
  static fs::path* dir_;
};
fs::path* ExportCli::dir_ = nullptr;

TEST_F(ExportCli, EveryFormatWritesTheResultAndComparesBackToIt) {
  const Pose cam_from_lidar = LoadResult(Result()).cam_from_source;
  for (const ExportFormat format : AllExportFormats()) {
    for (const char* camera_frame : {"optical", "link"}) {
      const std::string name = ExportFormatName(format);
      const fs::path out =
          *dir_ / (std::string(camera_frame) + "_" + DefaultExportFileName(format));
      std::string output;
      ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + Result().string() +
                                     " --format " + name +
                                     " --parent-frame velodyne "
                                     "--child-frame cam0 --camera-frame " +
                                     camera_frame + " --out " + out.string(),
                                 &output),
                0)
          << output;
      EXPECT_NE(output.find("the pose of 'cam0' in 'velodyne'"), std::string::npos) << output;
      if (format == ExportFormat::kRos2Tf) {
        EXPECT_NE(output.find("ros2 run tf2_ros static_transform_publisher --x"), std::string::npos)
            << output;
      }
      ExportFrames frames;
      frames.lidar = "velodyne";
      frames.camera = "cam0";
      frames.camera_frame = *ParseCameraFrame(camera_frame);
      const ImportedTransform imported = ReadExportedTransform(out);
      EXPECT_TRUE(test::MatrixNear(CamFromLidarOf(imported.parent_from_child, frames).matrix(),
                                   cam_from_lidar.matrix(), 1e-12))
          << name << " " << camera_frame;
      ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " evaluate --result " + Result().string() +
                                     " --reference " + out.string() + " --reference-camera-frame " +
                                     camera_frame +
                                     " --max-translation-mm 0.001 --max-rotation-deg 0.00001",
                                 &output),
                0)
          << output;
      EXPECT_NE(output.find("translation 0.00 mm"), std::string::npos) << output;
    }
  }
}

TEST_F(ExportCli, TheWrongConventionShowsAsALargeDifference) {
  const fs::path out = *dir_ / "link.urdf";
  std::string output;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + Result().string() +
                                 " --format urdf --camera-frame link --out " + out.string(),
                             &output),
            0)
      << output;
  // Read as if it were optical: 120 degrees off (the REP 103 rotation), and exit 5 on the bound.
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " evaluate --result " + Result().string() +
                                 " --reference " + out.string() + " --max-rotation-deg 1",
                             &output),
            5)
      << output;
  EXPECT_NE(output.find("rotation 120.000 deg"), std::string::npos) << output;
}

// --swap makes the camera the parent: the frames keep their own names whichever flags name them
// (it named the camera's frame "lidar" without them), and the file reads back to the result.
TEST_F(ExportCli, SwappedTheCameraIsTheParentUnderItsOwnName) {
  const Pose cam_from_lidar = LoadResult(Result()).cam_from_source;
  for (const std::string names : {"", " --parent-frame cam0 --child-frame velodyne"}) {
    const fs::path out = *dir_ / "swapped.urdf";
    std::string output;
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --swap --format urdf --result " +
                                   Result().string() + names + " --out " + out.string(),
                               &output),
              0)
        << output;
    ExportFrames frames;
    frames.camera_is_parent = true;
    if (!names.empty()) frames.camera = "cam0", frames.lidar = "velodyne";
    EXPECT_NE(output.find("the pose of '" + frames.lidar + "' in '" + frames.camera + "'"),
              std::string::npos)
        << output;
    const ImportedTransform imported = ReadExportedTransform(out);
    EXPECT_TRUE(test::MatrixNear(CamFromLidarOf(imported.parent_from_child, frames).matrix(),
                                 cam_from_lidar.matrix(), 1e-12))
        << names;
  }
}

TEST_F(ExportCli, BadFlagsAndASessionWithoutAResult) {
  std::string output;
  EXPECT_EQ(test::RunCommand(
                test::CalibenchExe() + " export --result " + Result().string() + " --format sdf",
                &output),
            1);
  EXPECT_NE(output.find("--format must be urdf | ros1-tf"), std::string::npos) << output;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + Result().string() +
                                 " --format txt --parent-frame x --child-frame x",
                             &output),
            1);
  EXPECT_NE(output.find("must differ"), std::string::npos) << output;
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " +
                                 (*dir_ / "missing.json").string() + " --format txt",
                             &output),
            2);
  EXPECT_NE(output.find("missing.json"), std::string::npos) << output;

  // A session works in place of a result once it has one.
  Session session = NewSession(LoadDataset(*dir_ / "data"));
  const fs::path session_path = *dir_ / "data" / "work.session.json";
  SaveSession(session_path, session);
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + session_path.string() +
                                 " --format txt --out " + (*dir_ / "s.txt").string(),
                             &output),
            2);
  EXPECT_NE(output.find("the session has no result yet"), std::string::npos) << output;
  session.result = SessionResult{};
  session.result->cam_from_lidar = LoadResult(Result()).cam_from_source;
  SaveSession(session_path, session);
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + session_path.string() +
                                 " --format txt --out " + (*dir_ / "s.txt").string(),
                             &output),
            0)
      << output;
  EXPECT_TRUE(test::MatrixNear(ReadExportedTransform(*dir_ / "s.txt").parent_from_child.matrix(),
                               LoadResult(Result()).cam_from_source.inverse().matrix(), 1e-12));
}

}  // namespace
}  // namespace calibench
