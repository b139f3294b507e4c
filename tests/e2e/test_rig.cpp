// A rig of one LiDAR and two cameras — a pinhole and a fisheye turned 60° aside, their fields
// overlapping partly — simulated in the rig's folder form and calibrated in one command:
// each camera within the single-camera bar, and the cameras' relative pose from the rig solve
// next to the one composed from the two single-camera results.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "core/capture/bag_import.h"
#include "core/geometry/geometry.h"
#include "core/io/dataset.h"
#include "core/recording/bag.h"
#include "core/sim/rig_sim.h"
#include "tests/bag_writers.h"
#include "tests/sim_recording.h"
#include "tests/test_support.h"
#include "tests/watch_stream.h"

namespace calibench {
namespace {

using test::PoseFromRows;

TEST(Rig, APinholeAndAFisheyeAsideCalibrateTogetherInOneCommand) {
  const auto dir = test::TempDir("rig_two_cameras");
  RigSimOptions sim;
  sim.base = SimPreset("default");
  sim.base.min_distance_m = 1.2;
  sim.base.max_distance_m = 2.5;
  sim.base.lidar_range_noise_m = 0.005;
  sim.base.image_noise = 0.005;
  sim.base.seed = 23;
  sim.num_captures = 30;
  const RigSimTruth truth = SimulateRigFolder(sim, dir / "rig");
  std::printf("%d captures, %d seen by both cameras\n", sim.num_captures, truth.shared_captures);
  ASSERT_GE(truth.shared_captures, 4);

  std::string out;
  const auto result_path = dir / "rig.json";
  const auto report_path = dir / "rig_report.html";
  ASSERT_EQ(
      test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + (dir / "rig").string() +
                           " --out " + result_path.string() + " --report " + report_path.string(),
                       &out),
      0)
      << out;
  std::printf("%s", out.c_str());
  const nlohmann::json result = nlohmann::json::parse(std::ifstream(result_path));
  EXPECT_EQ(result["format"], "calibench.rig.v1");
  ASSERT_TRUE(result["cameras"].contains("cam0") && result["cameras"].contains("cam1"));
  Pose joint[2], single[2];
  for (int c = 0; c < 2; ++c) {
    const nlohmann::json& camera = result["cameras"]["cam" + std::to_string(c)];
    joint[c] = PoseFromRows(camera["cam_from_lidar"]);
    single[c] = PoseFromRows(camera["single_camera"]["matrix"]);
    EXPECT_EQ(camera["sigma_translation_mm"].size(), 3u);
    const PoseError e = ComputePoseError(joint[c], truth.cam_from_lidar[c]);
    const PoseError s = ComputePoseError(single[c], truth.cam_from_lidar[c]);
    std::printf("cam%d: rig %.2f mm %.3f deg, alone %.2f mm %.3f deg from the truth\n", c,
                e.translation_m * 1e3, e.rotation_rad * 180 / M_PI, s.translation_m * 1e3,
                s.rotation_rad * 180 / M_PI);
    // The single-camera bar (tests/e2e/test_simulated.cpp): 25 mm and 0.6 deg.
    EXPECT_LT(e.translation_m, 0.025) << c;
    EXPECT_LT(e.rotation_rad, 0.6 * M_PI / 180) << c;
    // Each camera's own calibration is the rig's prior: the rig does not make it worse.
    EXPECT_LT(e.translation_m, 1.1 * s.translation_m + 0.0002) << c;
  }
  const Pose true_relative = truth.cam_from_lidar[1] * truth.cam_from_lidar[0].inverse();
  const Pose written = PoseFromRows(result["camera_from_camera"]["cam1_from_cam0"]["matrix"]);
  EXPECT_LT((written.matrix() - (joint[1] * joint[0].inverse()).matrix()).norm(), 1e-9);
  const PoseError rig = ComputePoseError(written, true_relative);
  const PoseError composed = ComputePoseError(single[1] * single[0].inverse(), true_relative);
  std::printf("cam1_from_cam0: rig %.2f mm %.3f deg, composed %.2f mm %.3f deg from the truth\n",
              rig.translation_m * 1e3, rig.rotation_rad * 180 / M_PI, composed.translation_m * 1e3,
              composed.rotation_rad * 180 / M_PI);
  EXPECT_LT(rig.translation_m, 0.025);
  EXPECT_LT(rig.rotation_rad, 0.6 * M_PI / 180);
  // The boards both cameras saw tie them: better than composing the two single results.
  EXPECT_LT(rig.translation_m, 0.5 * composed.translation_m);
  EXPECT_LT(rig.rotation_rad, 0.5 * composed.rotation_rad);

  // The report shows the rig (each camera's pose from the rig solve next to its own, the relative
  // pose as the result has it) and then each camera as one camera's report does.
  std::ifstream report_file(report_path);
  const std::string html((std::istreambuf_iterator<char>(report_file)), {});
  EXPECT_NE(html.find("Calibench rig calibration report"), std::string::npos);
  for (const char* row :
       {"data-rig-camera=\"cam0\"", "data-rig-camera=\"cam1\"", "data-relative=\"cam1_from_cam0\"",
        "Camera cam0 alone", "Camera cam1 alone", "id=\"camera0-residuals\"",
        "id=\"camera1-coverage-image\"", "id=\"camera1-pairs\""})
    EXPECT_NE(html.find(row), std::string::npos) << row;
  char translation[96];
  std::snprintf(translation, sizeof(translation), "%.4f %.4f %.4f", written.translation().x(),
                written.translation().y(), written.translation().z());
  EXPECT_NE(html.find(translation), std::string::npos) << translation;
  // Every pair of each camera has its row in that camera's table.
  for (int c = 0; c < 2; ++c) {
    const size_t section = html.find("id=\"camera" + std::to_string(c) + "-pairs\"");
    const size_t next = html.find("</section>", section);
    ASSERT_NE(section, std::string::npos);
    int rows = 0;
    for (size_t at = html.find("data-pair=", section); at < next;
         at = html.find("data-pair=", at + 1))
      ++rows;
    int frames = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(dir / "rig" / "images" / ("cam" + std::to_string(c))))
      frames += entry.is_regular_file();
    EXPECT_EQ(rows, frames) << "cam" << c;
  }
  // The views need a headless OpenGL, which CI requires (CALIBENCH_REQUIRE_GL=1).
  if (const char* gl = std::getenv("CALIBENCH_REQUIRE_GL"); gl && std::string(gl) == "1") {
    EXPECT_NE(html.find("rig's cameras (cam0 in orange)"), std::string::npos);
    EXPECT_NE(html.find("rig's cameras (cam1 in orange)"), std::string::npos);
  }

  // The tree a robot loads: a URDF with a joint per camera, which urdfdom's parser accepts, and
  // whose joints read back as the rig's poses; the ROS 2 launch file with a publisher per camera.
  const auto urdf = dir / "rig.urdf";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + result_path.string() +
                                 " --format urdf --parent-frame velodyne --out " + urdf.string(),
                             &out),
            0)
      << out;
  ASSERT_EQ(test::RunCommand("check_urdf " + urdf.string(), &out), 0)
      << out << "(check_urdf comes with Debian's liburdfdom-tools: scripts/install_deps.sh)";
  EXPECT_NE(out.find("root Link: velodyne has 2 child(ren)"), std::string::npos) << out;
  EXPECT_NE(out.find("child(1):  cam0"), std::string::npos) << out;
  EXPECT_NE(out.find("child(2):  cam1"), std::string::npos) << out;
  const auto launch = dir / "rig.launch.py";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + result_path.string() +
                                 " --format ros2-tf --out " + launch.string(),
                             &out),
            0)
      << out;
  std::ifstream launch_file(launch);
  const std::string text((std::istreambuf_iterator<char>(launch_file)), {});
  EXPECT_NE(text.find("\"--child-frame-id\", \"cam0\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"--child-frame-id\", \"cam1\""), std::string::npos) << text;
  // Autoware's sensor kit file and a Kalibr camchain hold the tree too; a format that holds one
  // transform says so.
  for (const char* format : {"autoware", "kalibr"}) {
    const auto file = dir / (std::string(format) + ".yaml");
    ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " + result_path.string() +
                                   " --format " + format + " --out " + file.string(),
                               &out),
              0)
        << out;
    std::ifstream in(file);
    const std::string yaml((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(yaml.find(std::string(format) == "kalibr" ? "T_cn_cnm1" : "  cam1:"),
              std::string::npos)
        << yaml;
  }
  EXPECT_NE(test::RunCommand(test::CalibenchExe() + " export --result " + result_path.string() +
                                 " --format opencv-yaml --out " + (dir / "o.yaml").string(),
                             &out),
            0);
  EXPECT_NE(out.find("holds one transform"), std::string::npos) << out;

  // A frame that cannot be read is said as for one camera: named with its camera, the rig solved
  // from the rest, exit 2 (kInputError).
  std::set<std::filesystem::path> frames;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "rig" / "images" / "cam1"))
    frames.insert(entry.path());
  ASSERT_FALSE(frames.empty());
  const std::filesystem::path broken = *frames.begin();
  std::ofstream(broken, std::ios::trunc) << "not an image";
  const auto partial = dir / "partial.json";
  EXPECT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 (dir / "rig").string() + " --out " + partial.string(),
                             &out),
            2)
      << out;
  EXPECT_NE(out.find("some pair files could not be read; the result uses the remaining pairs:"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("camera cam1 pair " + broken.stem().string() + ": cannot read image"),
            std::string::npos)
      << out;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(partial))["format"], "calibench.rig.v1");
}

// The rig's manifest (cameras by name, each pair's frames by camera) calibrates as its folder; one
// camera of it alone is that camera's own result.
TEST(Rig, AManifestNamingItsCamerasCalibratesAsItsFolder) {
  const auto dir = test::TempDir("rig_manifest_cli");
  RigSimOptions sim;
  sim.base = SimPreset("default");
  sim.base.min_distance_m = 1.2;
  sim.base.max_distance_m = 2.5;
  sim.base.seed = 5;
  sim.num_captures = 14;
  const RigSimTruth truth = SimulateRigFolder(sim, dir / "rig");
  nlohmann::json manifest = {
      {"format", "calibench.dataset.v1"},
      {"cameras",
       {{"front", {{"file", "rig/cameras/cam0.yaml"}}},
        {"side", {{"file", "rig/cameras/cam1.yaml"}}}}},
      {"target", nlohmann::json::parse(std::ifstream(dir / "rig" / "target.json"))},
      {"pairs", nlohmann::json::array()}};
  for (const auto& entry : std::filesystem::directory_iterator(dir / "rig" / "clouds")) {
    const std::string stem = entry.path().stem().string();
    nlohmann::json images = nlohmann::json::object();
    for (const auto& [camera, name] : {std::pair{"cam0", "front"}, std::pair{"cam1", "side"}})
      if (std::filesystem::exists(dir / "rig" / "images" / camera / (stem + ".png")))
        images[name] = "rig/images/" + std::string(camera) + "/" + stem + ".png";
    manifest["pairs"].push_back(
        {{"id", stem}, {"cloud", "rig/clouds/" + stem + ".pcd"}, {"images", images}});
  }
  manifest["ground_truth"]["cameras"]["front"]["cam_from_lidar"] = {
      {1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  std::ofstream(dir / "rig.json") << manifest.dump(2);

  std::string out;
  ASSERT_EQ(
      test::RunCommand(test::CalibenchExe() + " calibrate --dataset " + (dir / "rig").string() +
                           " --out " + (dir / "folder_result.json").string(),
                       &out),
      0)
      << out;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 (dir / "rig.json").string() + " --out " +
                                 (dir / "manifest_result.json").string(),
                             &out),
            0)
      << out;
  const auto folder = nlohmann::json::parse(std::ifstream(dir / "folder_result.json"));
  const auto named = nlohmann::json::parse(std::ifstream(dir / "manifest_result.json"));
  ASSERT_TRUE(named["cameras"].contains("front") && named["cameras"].contains("side")) << named;
  for (const auto& [camera, name] : {std::pair{"cam0", "front"}, std::pair{"cam1", "side"}}) {
    const Pose a = PoseFromRows(folder["cameras"][camera]["cam_from_lidar"]);
    const Pose b = PoseFromRows(named["cameras"][name]["cam_from_lidar"]);
    EXPECT_LT((a.matrix() - b.matrix()).norm(), 1e-12) << name;
  }
  EXPECT_TRUE(named["camera_from_camera"].contains("side_from_front")) << named;
  const PoseError side = ComputePoseError(PoseFromRows(named["cameras"]["side"]["cam_from_lidar"]),
                                          truth.cam_from_lidar[1]);
  EXPECT_LT(side.translation_m, 0.025);

  // report on a rig result: the rig solved again, each camera against the file's, one page.
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " report --result " +
                                 (dir / "manifest_result.json").string() + " --dataset " +
                                 (dir / "rig.json").string() + " --no-views --no-cross-validation" +
                                 " --out " + (dir / "report.html").string(),
                             &out),
            0)
      << out;
  EXPECT_EQ(out.find("differs from a re-solve"), std::string::npos) << out;
  std::ifstream report_file(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(report_file)), {});
  EXPECT_NE(html.find("data-relative=\"side_from_front\""), std::string::npos);
  EXPECT_NE(html.find("Camera side alone"), std::string::npos);
  EXPECT_NE(test::RunCommand(test::CalibenchExe() + " report --result " +
                                 (dir / "manifest_result.json").string() + " --out " +
                                 (dir / "r.html").string(),
                             &out),
            0);
  EXPECT_NE(out.find("a rig result: give --dataset"), std::string::npos) << out;

  // advise: every camera against the goal, and the rig done only when every camera is.
  ASSERT_EQ(
      test::RunCommand(
          test::CalibenchExe() + " advise --json --dataset " + (dir / "rig.json").string(), &out),
      0)
      << out;
  // The one JSON object on stdout (the progress lines go to stderr, captured with it here).
  const std::string lines = "\n" + out;
  const size_t object = lines.find("\n{");
  ASSERT_NE(object, std::string::npos) << out;
  const auto advice =
      nlohmann::json::parse(lines.substr(object + 1, lines.find('\n', object + 1) - object - 1));
  bool all_done = true;
  for (const char* name : {"front", "side"}) {
    ASSERT_TRUE(advice["cameras"].contains(name)) << advice;
    EXPECT_EQ(advice["cameras"][name]["pairs_used"], named["cameras"][name]["pairs"]) << name;
    all_done = all_done && advice["cameras"][name]["done"].get<bool>();
  }
  EXPECT_EQ(advice["done"].get<bool>(), all_done);

  // --camera: that camera alone, a one-camera result equal to the rig result's single_camera.
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 (dir / "rig.json").string() + " --camera side --out " +
                                 (dir / "side.json").string(),
                             &out),
            0)
      << out;
  const auto alone = nlohmann::json::parse(std::ifstream(dir / "side.json"));
  EXPECT_EQ(alone["format"], "calibench.result.v1");
  EXPECT_LT((PoseFromRows(alone["cam_from_lidar"]["matrix"]).matrix() -
             PoseFromRows(named["cameras"]["side"]["single_camera"]["matrix"]).matrix())
                .norm(),
            1e-12);
  EXPECT_NE(test::RunCommand(test::CalibenchExe() + " calibrate --dataset " +
                                 (dir / "rig.json").string() + " --camera rear",
                             &out),
            0);
  EXPECT_NE(out.find("no camera 'rear' (its cameras: front, side)"), std::string::npos) << out;
}

// A recording with two camera topics (an MCAP as `ros2 bag record` writes it: a VLP-16 and two
// cameras, the second turned 25° aside) imported into the rig's folder form and calibrated in one
// command; the tree it exports loads in urdfdom.
TEST(Rig, ARecordingWithTwoCameraTopicsIsImportedAndCalibratedInOneCommand) {
  const auto dir = test::TempDir("rig_recording");
  test::SimRecordingOptions options = test::SmallSimRecording(10);
  options.second_camera_yaw_deg = 25.0;
  auto writer = test::OpenMcapWriter(dir / "rig.mcap", "ros2", "lz4", /*summary=*/true);
  const test::SimRecordingTruth truth =
      test::WriteSimRecording(writer.get(), MessageEncoding::kCdr, options);
  writer->Close();
  SaveTargetFile(dir / "target.json", truth.board);  // the board, kept beside the recording
  // Both cameras are found by themselves: the image topics with a CameraInfo beside them.
  EXPECT_EQ(CameraTopicsWithInfo(*OpenBag(dir / "rig.mcap")),
            (std::vector<std::string>{"/cam0/image_raw", "/cam1/image_raw"}));
  std::string out;
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " import " + (dir / "rig.mcap").string() +
                                 " --camera-topic /cam0/image_raw --camera-topic /cam1/image_raw"
                                 " --out " +
                                 (dir / "rig").string() + " --calibrate",
                             &out),
            0)
      << out;
  std::printf("%s", out.c_str());
  const nlohmann::json result = nlohmann::json::parse(std::ifstream(dir / "rig" / "rig.json"));
  const Pose truths[2] = {truth.cam_from_lidar, *truth.second_cam_from_lidar};
  for (int c = 0; c < 2; ++c) {
    const std::string name = "cam" + std::to_string(c);
    ASSERT_TRUE(result["cameras"].contains(name)) << result.dump(2);
    const PoseError e =
        ComputePoseError(PoseFromRows(result["cameras"][name]["cam_from_lidar"]), truths[c]);
    std::printf("%s from the recording: %.2f mm, %.3f deg from the truth\n", name.c_str(),
                e.translation_m * 1e3, e.rotation_rad * 180 / M_PI);
    EXPECT_LT(e.translation_m, 0.025) << name;
    EXPECT_LT(e.rotation_rad, 0.6 * M_PI / 180) << name;
  }
  EXPECT_GE(result["shared_captures"].get<int>(), 1);
  const auto urdf = dir / "rig.urdf";
  ASSERT_EQ(test::RunCommand(test::CalibenchExe() + " export --result " +
                                 (dir / "rig" / "rig.json").string() + " --format urdf --out " +
                                 urdf.string(),
                             &out),
            0)
      << out;
  ASSERT_EQ(test::RunCommand("check_urdf " + urdf.string(), &out), 0) << out;
  EXPECT_NE(out.find("root Link: lidar has 2 child(ren)"), std::string::npos) << out;
}

}  // namespace
}  // namespace calibench
