// The rig's folder form (core/io/rig_folder.h) and the names a rig import gives its cameras
// (core/io/rig_import.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/io/rig_folder.h"
#include "core/io/rig_import.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

void Touch(const fs::path& path) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << "x";
}

// cam0 sees captures 0000-0002, cam1 only 0001 and 0002 (and a frame without a cloud).
fs::path TwoCameraFolder(const std::string& name) {
  const fs::path dir = test::TempDir(name);
  for (const char* stem : {"0000", "0001", "0002"})
    Touch(dir / "clouds" / (std::string(stem) + ".pcd"));
  for (const char* stem : {"0000", "0001", "0002"})
    Touch(dir / "images" / "cam0" / (std::string(stem) + ".png"));
  for (const char* stem : {"0001", "0002", "0003"})
    Touch(dir / "images" / "cam1" / (std::string(stem) + ".png"));
  fs::create_directories(dir / "cameras");
  SaveCameraFile(dir / "cameras" / "cam0.yaml", DefaultSimCamera(false),
                 CameraFileFormat::kRosCameraInfo);
  SaveCameraFile(dir / "cameras" / "cam1.yaml", DefaultSimCamera(true),
                 CameraFileFormat::kRosCameraInfo);
  SaveTargetFile(dir / "target.json", ResolveSimOptions(SimOptions{}).board);
  return dir;
}

TEST(RigFolder, EachCameraIsADatasetOfTheCapturesItHasAFrameOf) {
  const fs::path dir = TwoCameraFolder("rig_folder");
  EXPECT_TRUE(IsRigFolder(dir));
  const RigFolder rig = LoadRigFolder(dir);
  ASSERT_EQ(rig.camera_names, (std::vector<std::string>{"cam0", "cam1"}));
  ASSERT_EQ(rig.cameras[0].pairs.size(), 3u);
  ASSERT_EQ(rig.cameras[1].pairs.size(), 2u);
  EXPECT_EQ(rig.cameras[1].pairs[0].id, "0001");
  EXPECT_EQ(rig.cameras[1].pairs[0].image, dir / "images" / "cam1" / "0001.png");
  EXPECT_EQ(rig.cameras[1].pairs[0].cloud, dir / "clouds" / "0001.pcd");
  EXPECT_EQ(rig.cameras[1].camera.type, CameraModelType::kKannalaBrandt);
  // The commands that take one camera say what a rig folder is and which command takes it.
  try {
    LoadDataset(dir);
    ADD_FAILURE() << "a rig folder read as one camera's dataset";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("a rig folder"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("calibench calibrate --dataset"), std::string::npos);
  }
}

void ExpectRejected(const fs::path& dir, const std::string& problem) {
  try {
    LoadRigFolder(dir);
    ADD_FAILURE() << "read a broken rig folder; expected: " << problem;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

TEST(RigFolder, ABrokenRigFolderNamesWhatIsMissing) {
  const fs::path dir = TwoCameraFolder("rig_folder_broken");
  fs::remove_all(dir / "images" / "cam1");
  ExpectRejected(dir, "camera 'cam1' has no images/cam1/ folder");
  fs::create_directories(dir / "images" / "cam1");
  Touch(dir / "images" / "cam1" / "9999.png");
  ExpectRejected(dir, "no frame shares a stem with a cloud");
  fs::remove(dir / "target.json");
  ExpectRejected(dir, "rig folder has no target.json");
  fs::remove_all(dir / "cameras");
  EXPECT_FALSE(IsRigFolder(dir));
  ExpectRejected(dir, "not a rig folder");
}

TEST(RigImport, CamerasAreNamedAfterTheirTopics) {
  EXPECT_EQ(RigCameraName("/cam1/image_raw"), "cam1");
  EXPECT_EQ(RigCameraName("/front/camera/image/compressed"), "front");
  EXPECT_EQ(RigCameraName("/camera/left/image_rect"), "left");
  EXPECT_EQ(RigCameraName("/camera/image_raw"), "camera_image_raw");
}

}  // namespace
}  // namespace calibench
