// The rig's folder form (core/io/rig_folder.h) and the names a rig import gives its cameras
// (core/capture/rig_import.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/capture/rig_import.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/io/rig_folder.h"
#include "core/session/session.h"
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

// The manifest form of TwoCameraFolder: cam0 from its file, cam1 inline, a pair's images by
// camera, a ground truth per camera.
void WriteRigManifest(const fs::path& dir, const std::string& extra_pair = "") {
  const CameraModel fisheye = DefaultSimCamera(true);
  std::ofstream(dir / "rig.json") << R"({"format": "calibench.dataset.v1",
  "cameras": {"cam0": {"file": "cameras/cam0.yaml"},
              "cam1": {"model": "kannala-brandt", "width": )"
                                  << fisheye.width << ", \"height\": " << fisheye.height
                                  << ", \"fx\": " << fisheye.fx << ", \"fy\": " << fisheye.fy
                                  << ", \"cx\": " << fisheye.cx << ", \"cy\": " << fisheye.cy
                                  << R"(, "distortion": [0.01, 0.0, 0.0, 0.0]}},
  "target": )" << std::ifstream(dir / "target.json").rdbuf()
                                  << R"(,
  "pairs": [
    {"id": "0000", "cloud": "clouds/0000.pcd", "images": {"cam0": "images/cam0/0000.png"}},
    {"id": "0001", "cloud": "clouds/0001.pcd",
     "images": {"cam0": "images/cam0/0001.png", "cam1": "images/cam1/0001.png"},
     "lidar_seed": {"point": [3, 0, 0], "radius": 0.3}},
    {"id": "0002", "cloud": "clouds/0002.pcd",
     "images": {"cam0": "images/cam0/0002.png", "cam1": "images/cam1/0002.png"}})"
                                  << extra_pair << R"(],
  "ground_truth": {"cameras": {"cam1": {"cam_from_lidar": [[1,0,0,0.1],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}}}
})";
}

TEST(RigManifest, NamesItsCamerasAndEachPairsFrameByCamera) {
  const fs::path dir = TwoCameraFolder("rig_manifest");
  WriteRigManifest(dir);
  EXPECT_TRUE(IsRig(dir / "rig.json"));
  EXPECT_TRUE(IsRig(dir));
  const RigFolder folder = LoadRig(dir);
  const RigFolder rig = LoadRig(dir / "rig.json");
  ASSERT_EQ(rig.camera_names, folder.camera_names);
  for (size_t c = 0; c < 2; ++c) {
    ASSERT_EQ(rig.cameras[c].pairs.size(), folder.cameras[c].pairs.size()) << c;
    for (size_t i = 0; i < rig.cameras[c].pairs.size(); ++i) {
      EXPECT_EQ(rig.cameras[c].pairs[i].id, folder.cameras[c].pairs[i].id);
      EXPECT_EQ(rig.cameras[c].pairs[i].image, folder.cameras[c].pairs[i].image);
      EXPECT_EQ(rig.cameras[c].pairs[i].cloud, folder.cameras[c].pairs[i].cloud);
    }
    EXPECT_EQ(rig.cameras[c].camera_name, folder.camera_names[c]);
    EXPECT_EQ(rig.cameras[c].camera.type, folder.cameras[c].camera.type);
  }
  EXPECT_DOUBLE_EQ(rig.cameras[1].camera.distortion[0], 0.01);
  ASSERT_TRUE(rig.cameras[0].pairs[1].lidar_seed.has_value());
  EXPECT_DOUBLE_EQ(rig.cameras[1].pairs[0].lidar_seed->radius, 0.3);  // the pair's, per camera
  EXPECT_FALSE(rig.cameras[0].cam_from_lidar_ground_truth.has_value());
  ASSERT_TRUE(rig.cameras[1].cam_from_lidar_ground_truth.has_value());
  EXPECT_DOUBLE_EQ(rig.cameras[1].cam_from_lidar_ground_truth->translation().x(), 0.1);

  // One camera of it, as the workbench and a camera's session open it.
  const Dataset cam1 = LoadRigCamera(dir / "rig.json", "cam1");
  EXPECT_EQ(cam1.camera_name, "cam1");
  EXPECT_EQ(cam1.pairs.size(), 2u);
  try {
    LoadRigCamera(dir / "rig.json", "left");
    ADD_FAILURE() << "a camera the rig has not";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no camera 'left' (its cameras: cam0, cam1)"),
              std::string::npos)
        << e.what();
  }
  // A one-camera command given the rig manifest says what it is and which commands take it.
  try {
    LoadDataset(dir / "rig.json");
    ADD_FAILURE() << "a rig manifest read as one camera's dataset";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("a rig manifest"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--camera <name>"), std::string::npos) << e.what();
  }
}

TEST(RigManifest, ABrokenManifestNamesTheMember) {
  const fs::path dir = TwoCameraFolder("rig_manifest_broken");
  WriteRigManifest(dir, R"(, {"id": "0003", "cloud": "c.pcd", "images": {"left": "l.png"}})");
  try {
    LoadRig(dir / "rig.json");
    ADD_FAILURE() << "a pair's frame of a camera the rig has not";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("pairs[3].images.left"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rig.json"), std::string::npos) << e.what();
  }
  WriteRigManifest(dir, R"(, {"id": "0002", "cloud": "c.pcd", "images": {}})");
  try {
    LoadRig(dir / "rig.json");
    ADD_FAILURE() << "a pair id twice";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("0002"), std::string::npos) << e.what();
  }
}

TEST(RigSession, ACamerasSessionNamesItAndOpensThatCamera) {
  const fs::path dir = TwoCameraFolder("rig_session");
  Session session = NewSession(LoadRigCamera(dir, "cam1"));
  EXPECT_EQ(session.camera, "cam1");
  EXPECT_EQ(DefaultSessionPath(dir, "cam1"), dir / "calibench.session.cam1.json");
  EXPECT_EQ(DefaultSessionPath(dir), dir / "calibench.session.json");
  const fs::path path = DefaultSessionPath(dir, "cam1");
  SaveSession(path, session);
  EXPECT_EQ(LoadSession(path), session);
  const auto [loaded, dataset] = LoadSessionWithDataset(path);
  EXPECT_EQ(dataset.camera_name, "cam1");
  EXPECT_EQ(dataset.pairs.size(), 2u);
  // A one-camera session writes no camera (the file is as before).
  Session single = session;
  single.camera.clear();
  EXPECT_EQ(SessionToJson(single, path).find("\"camera\":"), std::string::npos);
  EXPECT_NE(SessionToJson(session, path).find("\"camera\": \"cam1\""), std::string::npos);
}

// `calibrate --session` and `report --session` on a rig read the sessions one way: each edits its
// own camera; a session of another rig, of one camera's dataset or of a camera the rig has not is
// refused by name, not applied by its camera's name.
TEST(RigSession, EachSessionEditsItsCameraAndAnotherDatasetsIsRefused) {
  const fs::path dir = TwoCameraFolder("rig_session_edits");
  const RigFolder rig = LoadRigFolder(dir);
  Session session = NewSession(LoadRigCamera(dir, "cam1"));
  ASSERT_EQ(session.pairs.size(), 2u);
  session.pairs[1].status = PairStatus::kRejected;
  const fs::path path = DefaultSessionPath(dir, "cam1");
  SaveSession(path, session);
  const std::map<std::string, PairEdits> edits = RigEditsOfSessions(rig, {path.string()});
  ASSERT_EQ(edits.size(), 1u);
  ASSERT_EQ(edits.count("cam1"), 1u);
  EXPECT_TRUE(edits.at("cam1").at(session.pairs[1].id).rejected);
  EXPECT_TRUE(RigEditsOfSessions(rig, {}).empty());

  auto refused = [&](const Session& other, const fs::path& file, const std::string& named) {
    SaveSession(file, other);
    try {
      RigEditsOfSessions(rig, {path.string(), file.string()});
      ADD_FAILURE() << file << " was taken";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  const fs::path elsewhere = TwoCameraFolder("rig_session_elsewhere");
  refused(NewSession(LoadRigCamera(elsewhere, "cam1")), elsewhere / "calibench.session.cam1.json",
          (elsewhere / "calibench.session.cam1.json").string());
  Session no_camera = session;
  no_camera.camera.clear();
  refused(no_camera, dir / "one.json", "not a session of a camera of the rig");
  Session unknown = session;
  unknown.camera = "cam7";
  refused(unknown, dir / "cam7.json", "cam7");
}

TEST(RigImport, CamerasAreNamedAfterTheirTopics) {
  EXPECT_EQ(RigCameraName("/cam1/image_raw"), "cam1");
  EXPECT_EQ(RigCameraName("/front/camera/image/compressed"), "front");
  EXPECT_EQ(RigCameraName("/camera/left/image_rect"), "left");
  EXPECT_EQ(RigCameraName("/camera/image_raw"), "camera_image_raw");
}

}  // namespace
}  // namespace calibench
