// A rig in the workbench: one camera open with its own session, the rig's other cameras solved
// beside it (as `calibrate --dataset <rig>` solves them), the strip of the selected capture's
// frames, the meter over every camera; switching cameras in the window keeps each camera's edits,
// and the rig solve takes them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/session/session.h"
#include "core/sim/rig_sim.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller_outcome.h"
#include "ui/lidar_camera/window_shell.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

struct SimulatedRig {
  fs::path folder;
  RigSimTruth truth;
};

// A pinhole and a fisheye turned 60 degrees aside, a VLP-16, 16 captures (made once).
const SimulatedRig& Rig() {
  static const SimulatedRig rig = [] {
    SimulatedRig made;
    // Per process: ctest runs these tests in processes of their own, side by side.
    made.folder = test::TempDir("rig_workbench_" + std::to_string(getpid())) / "rig";
    RigSimOptions sim;
    sim.base = SimPreset("default");
    sim.base.min_distance_m = 1.2;
    sim.base.max_distance_m = 2.5;
    sim.base.seed = 31;
    sim.num_captures = 16;
    made.truth = SimulateRigFolder(sim, made.folder);
    return made;
  }();
  return rig;
}

// A rig folder of our own (the sessions a test writes stay its own).
fs::path CopyOfRig(const std::string& name) {
  const fs::path copy = test::TempDir(name) / "rig";
  fs::copy(Rig().folder, copy, fs::copy_options::recursive);
  return copy;
}

ui::Snapshot Settled(ui::Controller& controller) {
  controller.WaitRig();
  controller.WaitIdle();
  return controller.GetSnapshot();
}

TEST(RigWorkbench, ACameraOpensWithTheRigsOtherCamerasSolvedBesideIt) {
  const fs::path rig_path = CopyOfRig("rig_workbench_open");
  ui::Controller controller;
  controller.OpenDataset(rig_path, {}, ui::ExistingSession::kReplace, "cam0");
  Settled(controller);
  controller.Apply(ui::RunSolver{});
  const ui::Snapshot s = Settled(controller);
  ASSERT_TRUE(s.rig.has_value());
  ASSERT_EQ(s.rig->cameras.size(), 2u);
  EXPECT_EQ(s.rig->active, 0);
  EXPECT_EQ(s.dataset->camera_name, "cam0");
  EXPECT_FALSE(s.rig->solving);
  // Its own session, which names the camera.
  EXPECT_EQ(s.session_path, rig_path / "calibench.session.cam0.json");
  EXPECT_EQ(LoadSession(s.session_path).camera, "cam0");

  // Every camera's own solve and the rig solve, as `calibrate --dataset <rig>` computes them.
  const RigOutcome cli = CalibrateRig(LoadRig(rig_path), PipelineOptions{});
  ASSERT_TRUE(cli.joint.has_value()) << cli.failure;
  for (int c = 0; c < 2; ++c) {
    const ui::RigCameraView& camera = s.rig->cameras[c];
    ASSERT_TRUE(camera.single && camera.joint_cam_from_lidar) << c << " " << camera.failure;
    EXPECT_LT(
        (camera.joint_cam_from_lidar->matrix() - cli.joint->cam_from_lidar[c].matrix()).norm(),
        1e-9)
        << c;
    const PoseError error =
        ComputePoseError(*camera.joint_cam_from_lidar, Rig().truth.cam_from_lidar[c]);
    std::printf("cam%d in the workbench's rig solve: %.2f mm %.3f deg from the truth\n", c,
                error.translation_m * 1e3, error.rotation_rad / kDegToRad);
    EXPECT_LT(error.translation_m, 0.025) << c;  // the single-camera bar
    EXPECT_LT(error.rotation_rad, 0.6 * kDegToRad) << c;
    // The meter covers every camera: the open one from its solve, the other from its own.
    ASSERT_TRUE(camera.meter.has_value()) << c;
    EXPECT_GT(camera.meter->pairs_used, 3) << c;
  }
  ASSERT_TRUE(s.solver.result.has_value()) << s.status_line;
  EXPECT_LT(
      (s.rig->cameras[0].single->cam_from_lidar.matrix() - s.solver.result->cam_from_lidar.matrix())
          .norm(),
      1e-12)
      << s.rig->cameras[0].single->cam_from_lidar.matrix() << "\n"
      << s.solver.result->cam_from_lidar.matrix() << "\n"
      << s.status_line;
  ASSERT_EQ(s.rig->relative.size(), 1u);
  EXPECT_EQ(s.rig->relative[0].name, "cam1_from_cam0");
  const Pose truth = Rig().truth.cam_from_lidar[1] * Rig().truth.cam_from_lidar[0].inverse();
  const PoseError relative = ComputePoseError(s.rig->relative[0].pose, truth);
  std::printf("cam1_from_cam0: %.2f mm %.3f deg from the truth (sigma %.2f mm)\n",
              relative.translation_m * 1e3, relative.rotation_rad / kDegToRad,
              s.rig->relative[0].sigma_t_mm.maxCoeff());
  EXPECT_LT(relative.translation_m, 0.005);
  EXPECT_LT(relative.rotation_rad, 0.1 * kDegToRad);

  // The strip: every camera's frame of the selected capture; none where a camera has no frame.
  ASSERT_FALSE(s.pairs.empty());
  for (int index = 0; index < static_cast<int>(s.pairs.size()); ++index) {
    controller.Apply(ui::SelectPair{index});
    const ui::Snapshot selected = Settled(controller);
    const std::string& id = selected.pairs[index].id;
    ASSERT_EQ(selected.rig->frames_pair, id);
    for (int c = 0; c < 2; ++c) {
      const bool has_frame =
          fs::exists(rig_path / "images" / ("cam" + std::to_string(c)) / (id + ".png"));
      EXPECT_EQ(selected.rig->cameras[c].frame != nullptr, has_frame) << id << " cam" << c;
    }
  }
}

TEST(RigWorkbench, SwitchingCamerasKeepsEachCamerasEditsAndTheRigSolveTakesThem) {
  const fs::path rig_path = CopyOfRig("rig_workbench_switch");
  ui::ShellOptions options;
  options.auto_solve = false;
  options.recent_file = rig_path.parent_path() / "recent.json";
  ui::WindowShell shell(options);
  shell.OpenDataset(rig_path, ui::ExistingSession::kReplace, "cam0");
  ui::Snapshot s = Settled(shell.controller());
  ASSERT_TRUE(s.rig.has_value());
  const int cam1_pairs = s.rig->cameras[1].pairs_used;
  ASSERT_GT(cam1_pairs, 4);
  // A capture both cameras saw, selected before the switch.
  const RigFolder rig = LoadRig(rig_path);
  std::string shared;
  for (const PairEntry& pair : rig.cameras[1].pairs)
    if (shared.empty() && pair.id != rig.cameras[0].pairs.front().id)
      for (const PairEntry& own : rig.cameras[0].pairs)
        if (own.id == pair.id) shared = pair.id;
  ASSERT_FALSE(shared.empty());
  for (int i = 0; i < static_cast<int>(s.pairs.size()); ++i)
    if (s.pairs[i].id == shared) shell.controller().Apply(ui::SelectPair{i});
  Settled(shell.controller());

  // To cam1: its own session, the rig's solves carried over (not solved again), the same capture.
  shell.SelectCamera("cam1");
  EXPECT_TRUE(shell.error().empty()) << shell.error();
  s = shell.controller().GetSnapshot();
  ASSERT_TRUE(s.rig.has_value());
  EXPECT_FALSE(s.rig->solving);
  EXPECT_EQ(s.rig->active, 1);
  ASSERT_TRUE(s.rig->cameras[0].single != nullptr);  // carried
  s = Settled(shell.controller());
  EXPECT_EQ(s.dataset->camera_name, "cam1");
  EXPECT_EQ(s.session_path, rig_path / "calibench.session.cam1.json");
  ASSERT_GE(s.selected, 0);
  EXPECT_EQ(s.pairs[s.selected].id, shared);
  // cam1's edit: a capture rejected, saved in cam1's session.
  shell.controller().Apply(ui::SetPairStatus{s.selected, PairStatus::kRejected});
  Settled(shell.controller());
  EXPECT_EQ(EditsFromSession(LoadSession(rig_path / "calibench.session.cam1.json")).size(), 1u);
  // Solved again without that capture, cam1 has moved from where the rig solve had it.
  EXPECT_FALSE(shell.controller().GetSnapshot().rig->JointStale());
  shell.controller().Apply(ui::RunSolver{});
  EXPECT_TRUE(Settled(shell.controller()).rig->JointStale());

  // Back to cam0; the rig solve takes cam1's edit from its session: one pair fewer.
  shell.SelectCamera("cam0");
  Settled(shell.controller());
  shell.controller().Apply(ui::SolveRig{});
  s = Settled(shell.controller());
  ASSERT_TRUE(s.rig.has_value());
  EXPECT_EQ(s.rig->cameras[1].pairs_used, cam1_pairs - 1);
  EXPECT_FALSE(s.rig->JointStale());
  // The same as the command line given cam1's session.
  const RigOutcome cli = CalibrateRig(
      rig, PipelineOptions{}, {},
      {{"cam1", EditsFromSession(LoadSession(rig_path / "calibench.session.cam1.json"))}});
  ASSERT_TRUE(cli.joint.has_value());
  EXPECT_LT(
      (s.rig->cameras[1].joint_cam_from_lidar->matrix() - cli.joint->cam_from_lidar[1].matrix())
          .norm(),
      1e-9);
  // A controller alone cannot switch (the window does); it says how.
  shell.controller().Apply(ui::SelectCamera{"cam1"});
  s = shell.controller().GetSnapshot();
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find("--camera cam1"), std::string::npos) << s.status_line;
}

TEST(RigWorkbench, ACameraTheRigHasNotIsAnErrorNamingItsCameras) {
  ui::Controller controller;
  try {
    controller.OpenDataset(Rig().folder, {}, ui::ExistingSession::kInMemory, "left");
    ADD_FAILURE() << "opened a camera the rig has not";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no camera 'left' (its cameras: cam0, cam1)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(controller.GetSnapshot().dataset.has_value());
}

// The rig solve runs in steps below the user's work on the one worker: an edit and its solve wait
// for the step that runs (one camera's calibration), not for the whole rig solve.
TEST(RigWorkbench, AnEditWhileTheRigSolvesWaitsForOneStepNotForTheSolve) {
  const fs::path rig_path = CopyOfRig("rig_workbench_steps");
  ui::Controller controller;
  controller.OpenDataset(rig_path, {}, ui::ExistingSession::kReplace, "cam0");
  // The open camera's pairs load first (queued jobs); the rig's steps wait below them.
  ui::Snapshot s = controller.GetSnapshot();
  for (int i = 0; i < 60000 && s.loading_done < s.loading_total; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s = controller.GetSnapshot();
  }
  ASSERT_EQ(s.loading_done, s.loading_total);
  ASSERT_TRUE(s.rig && s.rig->solving) << "steps: the rig read, each camera's, the joint solve";
  // Reject a pair and solve: the solve lands while the rig still solves (at most one camera's
  // step ran meanwhile: a background read, or a few pairs' extraction).
  controller.Apply(ui::SetPairStatus{1, PairStatus::kRejected});
  controller.Apply(ui::RunSolver{});
  std::vector<std::string> progress_seen;
  for (int i = 0; i < 120000 && !s.solver.result; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s = controller.GetSnapshot();
    if (s.rig && (progress_seen.empty() || progress_seen.back() != s.rig->progress))
      progress_seen.push_back(s.rig->progress);
  }
  ASSERT_TRUE(s.solver.result.has_value()) << s.status_line;
  EXPECT_TRUE(s.rig->solving) << "the solve waited for the whole rig solve";
  EXPECT_NE(s.rig->progress, "") << "the strip says which step the rig is at";
  for (const std::string& step : progress_seen) std::printf("rig step seen: '%s'\n", step.c_str());
  s = Settled(controller);
  EXPECT_FALSE(s.rig->solving);
  EXPECT_EQ(s.rig->progress, "");
  EXPECT_EQ(s.pairs[1].status, PairStatus::kRejected);
  // The rig solve took cam0's edits as they were when it started (none), as `calibrate` does
  // with an empty session: the joint pose is the command line's.
  const RigOutcome cli = CalibrateRig(LoadRig(rig_path), PipelineOptions{});
  ASSERT_TRUE(cli.joint && s.rig->cameras[1].joint_cam_from_lidar) << s.rig->failure;
  EXPECT_LT(
      (s.rig->cameras[1].joint_cam_from_lidar->matrix() - cli.joint->cam_from_lidar[1].matrix())
          .norm(),
      1e-9);
}

// One camera is a rig of one: the workbench sees a single camera's dataset as a rig with that
// camera alone, whose solve and meter are the workbench's own; the rig's solve (and its switch and
// strip) need a second camera. A report's snapshot of the same solve sees the same rig of one.
TEST(RigWorkbench, OneCameraIsARigOfOne) {
  ui::Controller controller;
  controller.OpenDataset(test::UiDataset(), {}, ui::ExistingSession::kInMemory);
  ui::Loaded(controller);
  controller.Apply(ui::RunSolver{});
  const ui::Snapshot s = Settled(controller);
  ASSERT_TRUE(s.rig.has_value());
  ASSERT_EQ(s.rig->cameras.size(), 1u);
  EXPECT_FALSE(s.rig->Several());
  EXPECT_EQ(s.rig->active, 0);
  EXPECT_EQ(s.rig->cameras[0].name, "camera");
  EXPECT_EQ(s.rig->path, s.dataset->manifest);
  EXPECT_EQ(s.rig->cameras[0].captures, static_cast<int>(s.pairs.size()));
  EXPECT_FALSE(s.rig->solving);
  ASSERT_TRUE(s.solver.result && s.rig->cameras[0].single);
  EXPECT_EQ(s.rig->cameras[0].single->cam_from_lidar.matrix(),
            s.solver.result->cam_from_lidar.matrix());
  ASSERT_TRUE(s.meter && s.rig->cameras[0].meter);
  EXPECT_EQ(s.rig->cameras[0].meter->done, s.meter->done);

  controller.Apply(ui::SolveRig{});
  const ui::Snapshot asked = Settled(controller);
  EXPECT_FALSE(asked.rig->solving);
  EXPECT_NE(asked.status_line.find("not a rig: there is one camera"), std::string::npos)
      << asked.status_line;

  const CalibrationOutcome cli = CalibrateDataset(*s.dataset, PipelineOptions{});
  ASSERT_TRUE(cli.solution) << cli.failure;
  const ui::Snapshot report = ui::SnapshotOfOutcome(*s.dataset, cli);
  ASSERT_TRUE(report.rig.has_value());
  ASSERT_EQ(report.rig->cameras.size(), 1u);
  EXPECT_EQ(report.rig->cameras[0].name, "camera");
  ASSERT_TRUE(report.rig->cameras[0].single);
  EXPECT_TRUE(test::MatrixNear(report.rig->cameras[0].single->cam_from_lidar.matrix(),
                               s.solver.result->cam_from_lidar.matrix(), 1e-12));
}

}  // namespace
}  // namespace calibench
