// One way to open a dataset (core/io/dataset_source.h): every command that takes --dataset opens
// a folder whose manifest is dataset.json, manifest.json or any other name, and the manifest
// file itself under any name; a folder of neither kind is refused by each with the same message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "core/io/dataset_source.h"
#include "core/results/result_file.h"
#include "core/sim/lrf_sim.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

class DatasetResolver : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(test::TempDir("dataset_resolver_" + std::to_string(getpid())));
    SimOptions sim = SimPreset("default");
    sim.num_pairs = 6;
    sim.seed = 3;
    SimulateDataset(sim, *dir_ / "lidar_camera");
    LrfSimOptions lrf = *LrfSimPreset("paper");
    lrf.observations = 6;
    WriteLrfSimDataset(lrf, *dir_ / "lrf");
    // The same datasets with their manifests renamed (the data files stay where they are, so
    // the relative paths inside still hold).
    Copy("lidar_camera", "lidar_camera_manifest", "dataset.json", "manifest.json");
    Copy("lidar_camera", "lidar_camera_named", "dataset.json", "rig_2026.json");
    Copy("lrf", "lrf_dataset", "manifest.json", "dataset.json");
    Copy("lrf", "lrf_named", "manifest.json", "scans_site_b.json");
    fs::create_directories(*dir_ / "neither");
    std::ofstream(*dir_ / "neither/notes.txt") << "not a dataset\n";
    std::ofstream(*dir_ / "neither/settings.json") << R"({"format": "something.else.v1"})";
  }
  static void TearDownTestSuite() { delete dir_; }

  static void Copy(const std::string& from, const std::string& to, const std::string& manifest,
                   const std::string& renamed) {
    fs::copy(*dir_ / from, *dir_ / to, fs::copy_options::recursive);
    fs::rename(*dir_ / to / manifest, *dir_ / to / renamed);
  }

  static int Run(const std::string& args, std::string* output) {
    return test::RunCommand(test::CalibenchExe() + " " + args, output);
  }
  static std::string Path(const std::string& relative) { return (*dir_ / relative).string(); }

  // The LiDAR-camera commands on `dataset`: calibrate, advise, evaluate (score and subsets).
  static void ExpectLidarCameraOpens(const std::string& dataset) {
    SCOPED_TRACE(dataset);
    std::string out;
    const std::string result = Path("result.json");
    ASSERT_EQ(Run("calibrate --dataset " + dataset + " --out " + result, &out), 0) << out;
    EXPECT_EQ(Run("advise --json --dataset " + dataset, &out), 0) << out;
    EXPECT_EQ(Run("evaluate --dataset " + dataset + " --result " + result, &out), 0) << out;
    EXPECT_NE(out.find("error against ground truth"), std::string::npos) << out;
    EXPECT_EQ(Run("evaluate --subsets --dataset " + dataset +
                      " --first-k 4 --random-sizes 4 --random-subsets 1",
                  &out),
              0)
        << out;
    // watch follows the folder (camera and target from the manifest, pairs from its files as
    // they come); its session goes elsewhere, so that the folder stays as the others found it.
    ASSERT_EQ(Run("watch " + dataset + " --json-lines --idle-exit 1 --session " +
                      Path("watch_session.json"),
                  &out),
              0)
        << out;
    size_t accepted = 0;
    for (size_t at = out.find("\"accepted\":true"); at != std::string::npos;
         at = out.find("\"accepted\":true", at + 1))
      ++accepted;
    EXPECT_EQ(accepted, 6u) << out;
    fs::remove(Path("watch_session.json"));
    fs::remove(Path("watch_session.features.jsonl"));
  }
  static void ExpectLrfOpens(const std::string& dataset) {
    SCOPED_TRACE(dataset);
    std::string out;
    const std::string result = Path("lrf_result.json");
    ASSERT_EQ(Run("lrf-calibrate --dataset " + dataset + " --out " + result, &out), 0) << out;
    EXPECT_EQ(Run("advise --dataset " + dataset, &out), 0) << out;
    EXPECT_EQ(Run("evaluate --dataset " + dataset + " --result " + result, &out), 0) << out;
  }
  // render draws without a window; a machine without any OpenGL (EGL, OSMesa) cannot, and says
  // so, unless CI requires it.
  static void ExpectRenders(const std::string& dataset, const std::string& view) {
    SCOPED_TRACE(dataset);
    std::string out;
    const int code = Run("render --dataset " + dataset + " --view " + view +
                             " --size 320x240 --out " + Path("view.png"),
                         &out);
    const bool no_gl = out.find("OpenGL") != std::string::npos ||
                       out.find("OSMesa") != std::string::npos ||
                       out.find("EGL") != std::string::npos;
    if (code != 0 && no_gl && !std::getenv("CALIBENCH_REQUIRE_GL")) return;
    EXPECT_EQ(code, 0) << out;
  }

  static fs::path* dir_;
};
fs::path* DatasetResolver::dir_ = nullptr;

TEST_F(DatasetResolver, RecognisesEachKindByContentWhateverItsName) {
  std::string why;
  const auto kind_of = [&](const std::string& relative) {
    const auto source = RecogniseDataset(*dir_ / relative, &why);
    EXPECT_TRUE(source) << relative << ": " << why;
    return source ? source->kind : DatasetKind::kRecording;
  };
  EXPECT_EQ(kind_of("lidar_camera"), DatasetKind::kLidarCamera);
  EXPECT_EQ(kind_of("lidar_camera_manifest"), DatasetKind::kLidarCamera);
  EXPECT_EQ(kind_of("lidar_camera_named"), DatasetKind::kLidarCamera);
  EXPECT_EQ(kind_of("lidar_camera_named/rig_2026.json"), DatasetKind::kLidarCamera);
  EXPECT_EQ(kind_of("lrf"), DatasetKind::kLrf);
  EXPECT_EQ(kind_of("lrf_dataset"), DatasetKind::kLrf);
  EXPECT_EQ(kind_of("lrf_named"), DatasetKind::kLrf);
  EXPECT_EQ(kind_of("lrf_named/scans_site_b.json"), DatasetKind::kLrf);
  // The folder form has no manifest.
  fs::create_directories(*dir_ / "folder_form");
  fs::create_directory_symlink(*dir_ / "lidar_camera/clouds", *dir_ / "folder_form/clouds");
  fs::create_directory_symlink(*dir_ / "lidar_camera/images", *dir_ / "folder_form/images");
  const auto folder = RecogniseDataset(*dir_ / "folder_form", &why);
  ASSERT_TRUE(folder) << why;
  EXPECT_TRUE(folder->folder_form);
  // Two manifests besides the usual names: which one is meant is the user's to say.
  Copy("lidar_camera_named", "two_manifests", "rig_2026.json", "rig_a.json");
  fs::copy_file(*dir_ / "two_manifests/rig_a.json", *dir_ / "two_manifests/rig_b.json");
  EXPECT_FALSE(RecogniseDataset(*dir_ / "two_manifests", &why));
  EXPECT_NE(why.find("rig_a.json, rig_b.json"), std::string::npos) << why;
}

// A folder's dataset.json cut mid-object (a copy interrupted, an editor's crash) beside another
// manifest: the folder's own manifest is broken, and the command says so with the parser's line
// and column; it never calibrates from the other file in its place.
TEST_F(DatasetResolver, ABrokenDatasetJsonIsRefusedNotSkippedForAnotherManifest) {
  Copy("lidar_camera", "broken_beside_another", "dataset.json", "rig_2026.json");
  const std::string good = test::ReadFileBytes(*dir_ / "broken_beside_another/rig_2026.json");
  std::ofstream(*dir_ / "broken_beside_another/dataset.json") << good.substr(0, good.size() / 2);
  const std::string folder = Path("broken_beside_another");
  std::string out;
  const std::string result = Path("broken_result.json");
  EXPECT_NE(Run("calibrate --dataset " + folder + " --out " + result, &out), 0) << out;
  EXPECT_NE(out.find(folder + "/dataset.json: not valid JSON"), std::string::npos) << out;
  EXPECT_NE(out.find("line "), std::string::npos) << out;
  EXPECT_NE(out.find("column "), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(result));
  EXPECT_NE(Run("advise --json --dataset " + folder, &out), 0) << out;
  EXPECT_NE(out.find("dataset.json: not valid JSON"), std::string::npos) << out;
  // Named outright, the other manifest opens.
  EXPECT_EQ(Run("calibrate --dataset " + folder + "/rig_2026.json --out " + result, &out), 0)
      << out;
}

TEST_F(DatasetResolver, LidarCameraCommandsOpenEveryManifestName) {
  ExpectLidarCameraOpens(Path("lidar_camera"));
  ExpectLidarCameraOpens(Path("lidar_camera_manifest"));
  ExpectLidarCameraOpens(Path("lidar_camera_named"));
  ExpectLidarCameraOpens(Path("lidar_camera_named/rig_2026.json"));
  ExpectRenders(Path("lidar_camera_manifest"), "lidar");
  ExpectRenders(Path("lidar_camera_named"), "lidar");
}

TEST_F(DatasetResolver, LrfCommandsOpenEveryManifestName) {
  ExpectLrfOpens(Path("lrf"));
  ExpectLrfOpens(Path("lrf_dataset"));  // the issue's case: an LRF manifest named dataset.json
  ExpectLrfOpens(Path("lrf_named"));
  ExpectLrfOpens(Path("lrf_named/scans_site_b.json"));
  ExpectRenders(Path("lrf_dataset"), "scan");
}

TEST_F(DatasetResolver, EveryCommandRefusesAFolderOfNeitherKindAlike) {
  const std::string neither = Path("neither");
  const std::vector<std::string> commands = {
      "calibrate --dataset " + neither + " --out " + Path("never.json"),
      "lrf-calibrate --dataset " + neither + " --out " + Path("never.json"),
      "advise --dataset " + neither,
      "evaluate --dataset " + neither + " --result " + Path("result.json"),
      "evaluate --subsets --dataset " + neither,
      "render --dataset " + neither + " --out " + Path("never.png"),
      "watch " + neither + " --idle-exit 1 --session " + Path("never_session.json"),
  };
  for (const std::string& command : commands) {
    SCOPED_TRACE(command);
    std::string out;
    EXPECT_NE(Run(command, &out), 0) << out;
    EXPECT_NE(out.find(neither + ": not a dataset folder (looked for a manifest"),
              std::string::npos)
        << out;
    // It lists what it looked for, and what it found instead.
    EXPECT_NE(out.find("dataset.json, manifest.json"), std::string::npos) << out;
    EXPECT_NE(out.find("clouds/ and images/"), std::string::npos) << out;
    EXPECT_NE(out.find("recording"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(*dir_ / "never.json"));
  }
}

TEST_F(DatasetResolver, AnotherKindIsRefusedWithTheCommandThatOpensIt) {
  std::string out;
  // `calibrate` runs either method's job (core/session/job.h): an LRF dataset solves as
  // `lrf-calibrate` solves it.
  const std::string lrf_result = Path("lrf_result.json");
  ASSERT_EQ(Run("calibrate --dataset " + Path("lrf_dataset") + " --out " + lrf_result, &out), 0)
      << out;
  EXPECT_NE(out.find("cam_from_lrf"), std::string::npos) << out;
  EXPECT_TRUE(IsLrfResultFile(lrf_result));
  // A command of the LiDAR-camera method alone refuses it, naming the one that opens it.
  EXPECT_NE(Run("check --dataset " + Path("lrf_dataset") + " --result " + lrf_result, &out), 0);
  EXPECT_NE(out.find("2D LRF dataset (calibench.lrf-dataset.v1)"), std::string::npos) << out;
  EXPECT_NE(out.find("calibench lrf-calibrate --dataset"), std::string::npos) << out;
  EXPECT_NE(
      Run("lrf-calibrate --dataset " + Path("lidar_camera") + " --out " + Path("never.json"), &out),
      0);
  EXPECT_NE(out.find("LiDAR-camera dataset (calibench.dataset.v1)"), std::string::npos) << out;
  EXPECT_NE(out.find("calibench calibrate --dataset"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
