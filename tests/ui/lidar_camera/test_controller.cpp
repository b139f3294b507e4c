// The workbench controller without any window: load, brush, accept/reject, solve, undo, sessions.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "core/session/session.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller.h"

namespace calibench::ui {
namespace {

TEST(Controller, LoadsEveryPairAndExtractsBothPlanes) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_load") / "s.json");
  const Snapshot s = Loaded(controller);
  ASSERT_EQ(s.pairs.size(), 4u);
  EXPECT_EQ(s.loading_done, 4);
  EXPECT_EQ(s.selected, 0);
  ASSERT_TRUE(s.selected_image);
  for (const PairView& p : s.pairs) {
    EXPECT_TRUE(p.loaded);
    EXPECT_EQ(p.status, PairStatus::kAccepted) << p.id << ": " << p.reason;
    EXPECT_TRUE(p.lidar) << p.lidar_failure;
    EXPECT_TRUE(p.camera) << p.camera_failure;
    EXPECT_FALSE(p.brush_pixels.empty());  // from the manifest's lidar_seed
    ASSERT_TRUE(p.thumbnail);
    EXPECT_EQ(p.thumbnail->width, 160);
  }
}

// A snapshot views the job's pairs: snapshots of an unchanged state share one list (a pointer
// copied, not the pairs), and an edit after a snapshot leaves that snapshot as it was.
TEST(Controller, SnapshotsShareOneImmutableViewOfThePairs) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_shared") / "s.json");
  const Snapshot before = Loaded(controller);
  ASSERT_EQ(before.pairs.size(), 4u);
  const Snapshot again = controller.GetSnapshot();
  EXPECT_TRUE(again.pairs.SharesWith(before.pairs));
  EXPECT_EQ(&again.pairs[1], &before.pairs[1]);
  controller.Apply(SetPairStatus{1, PairStatus::kRejected});
  const Snapshot after = controller.GetSnapshot();
  EXPECT_FALSE(after.pairs.SharesWith(before.pairs));
  EXPECT_EQ(after.pairs[1].status, PairStatus::kRejected);
  EXPECT_EQ(before.pairs[1].status, PairStatus::kAccepted);  // the old view stands
  EXPECT_EQ(again.pairs[1].status, PairStatus::kAccepted);
  EXPECT_EQ(after.pairs[0].cloud, before.pairs[0].cloud);  // the decoded files are shared too
  EXPECT_THROW(after.pairs.at(4), std::out_of_range);
}

TEST(Controller, BrushStrokesRefitThePlaneAndErasingRemovesIt) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_brush") / "s.json");
  Snapshot s = Loaded(controller);
  controller.Apply(ClearBrush{1});
  s = Loaded(controller);
  EXPECT_TRUE(s.pairs[1].brush_pixels.empty());
  EXPECT_FALSE(s.pairs[1].lidar);
  EXPECT_NE(s.pairs[1].lidar_failure.find("brush"), std::string::npos);
  EXPECT_EQ(s.pairs[1].status, PairStatus::kFailed);
  // Paint a disc where the board is (the pixel of a board inlier of another controller's fit).
  Controller reference;
  reference.OpenDataset(test::UiDataset(), test::TempDir("controller_brush_ref") / "s.json");
  const Snapshot r = Loaded(reference);
  const int inlier = r.pairs[1].lidar->inliers[r.pairs[1].lidar->inliers.size() / 2];
  const int pixel = r.pairs[1].lidar_image->pixel_of_point[inlier];
  const int columns = r.pairs[1].lidar_image->columns;
  controller.Apply(BrushStroke{1, pixel / columns, pixel % columns, 5.0f, false});
  s = Loaded(controller);
  ASSERT_TRUE(s.pairs[1].lidar) << s.pairs[1].lidar_failure;
  EXPECT_EQ(s.pairs[1].status, PairStatus::kAccepted);
  EXPECT_LT(
      std::acos(std::min(1.0, s.pairs[1].lidar->plane.normal.dot(r.pairs[1].lidar->plane.normal))),
      0.05);
  // Brush pixels (one return per LiDAR-image pixel) and the seed cone select slightly different
  // returns; the two fits agree within a few centimetres of d.
  EXPECT_NEAR(s.pairs[1].lidar->plane.distance, r.pairs[1].lidar->plane.distance, 0.03);
  // Erasing the same disc removes the region again.
  controller.Apply(BrushStroke{1, pixel / columns, pixel % columns, 5.0f, true});
  s = Loaded(controller);
  EXPECT_TRUE(s.pairs[1].brush_pixels.empty());
}

// The dabs of one stroke (mouse held down, then released) are one undo step.
TEST(Controller, OneBrushStrokeIsOneUndoStep) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_stroke") / "s.json");
  Snapshot s = Loaded(controller);
  const std::vector<int> seeded = s.pairs[1].brush_pixels;
  const int columns = s.pairs[1].lidar_image->columns;
  const int pixel = seeded[seeded.size() / 2];
  for (int step = 0; step < 5; ++step)  // a drag along the row
    controller.Apply(BrushStroke{1, pixel / columns, pixel % columns + 4 * step, 3.0f, false});
  controller.Apply(EndStroke{});
  s = Loaded(controller);
  const std::vector<int> first_stroke = s.pairs[1].brush_pixels;
  EXPECT_GT(first_stroke.size(), seeded.size());
  controller.Apply(BrushStroke{1, pixel / columns, pixel % columns + 40, 3.0f, false});
  controller.Apply(EndStroke{});
  Loaded(controller);
  controller.Apply(Undo{});  // the second stroke
  EXPECT_EQ(Loaded(controller).pairs[1].brush_pixels, first_stroke);
  controller.Apply(Undo{});  // the whole first stroke, all five dabs
  EXPECT_EQ(Loaded(controller).pairs[1].brush_pixels, seeded);
}

TEST(Controller, RejectAcceptSolveAndUndo) {
  Controller controller;
  const auto dir = test::TempDir("controller_solve");
  controller.OpenDataset(test::UiDataset(), dir / "s.json");
  Loaded(controller);
  controller.Apply(SetPairStatus{2, PairStatus::kRejected});
  Snapshot s = controller.GetSnapshot();
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  controller.Apply(RunSolver{});
  s = Loaded(controller);
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  EXPECT_TRUE(s.solver.result->converged);
  EXPECT_EQ(s.solver.solved_pair_ids.size(), 3u);
  EXPECT_GE(s.solver.iterations.size(), 2u);
  EXPECT_FALSE(s.pairs[2].residual);  // rejected: not in the solve
  EXPECT_TRUE(s.pairs[0].residual);
  ASSERT_TRUE(s.reprojection);
  EXPECT_GT(s.reprojection->points.size(), 100u);
  // Three A3 boards fix the extrinsic only roughly (the paper's N = 3 row); what matters here is
  // that the workbench solves what the batch pipeline solves from the same pairs.
  const Dataset dataset = LoadDataset(test::UiDataset());
  const PoseError error =
      ComputePoseError(s.solver.result->cam_from_lidar, *dataset.cam_from_lidar_ground_truth);
  EXPECT_LT(error.translation_m, 0.15);
  EXPECT_LT(error.rotation_rad, 2.0 * M_PI / 180);
  PipelineOptions batch;
  batch.pair_ids = {"0000", "0001", "0003"};
  const CalibrationOutcome reference = CalibrateDataset(dataset, batch);
  ASSERT_TRUE(reference.solution);
  const PoseError difference =
      ComputePoseError(s.solver.result->cam_from_lidar, reference.solution->cam_from_lidar);
  EXPECT_LT(difference.translation_m, 0.005);
  EXPECT_LT(difference.rotation_rad, 0.1 * M_PI / 180);
  ASSERT_TRUE(s.meter);  // the solve's σ against the goal
  // Undo brings the rejected pair back to accepted (the solve is undone first); the meter and the
  // next pose go with the solve.
  controller.Apply(Undo{});
  s = Loaded(controller);
  EXPECT_FALSE(s.solver.result);
  EXPECT_FALSE(s.meter);
  EXPECT_FALSE(s.next_pose);
  controller.Apply(Undo{});
  s = Loaded(controller);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kAccepted);
  controller.Apply(Redo{});
  s = Loaded(controller);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  controller.Apply(Redo{});  // the solve again: its σ judged again
  s = Loaded(controller);
  ASSERT_TRUE(s.solver.result);
  ASSERT_TRUE(s.meter);
}

// In the window the workbench solves by itself after each edit. That solve follows the edit: one
// undo takes back the rejection and the solve it caused (the calibration before it is back), and
// redo brings both again; the autosaved session says the same. Selecting pairs in between is no
// undo step.
TEST(Controller, WithAutoSolveOneUndoTakesBackAnEditAndTheSolveItCaused) {
  Controller controller;
  const auto dir = test::TempDir("controller_auto_undo");
  controller.SetAutoSolve(true);
  controller.OpenDataset(test::UiDataset(), dir / "s.json");
  Snapshot s = Loaded(controller);
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  EXPECT_EQ(s.solver.solved_pair_ids.size(), 4u);
  const Pose all_pairs = s.solver.result->cam_from_lidar;

  controller.Apply(SetPairStatus{2, PairStatus::kRejected});
  s = Loaded(controller);
  ASSERT_TRUE(s.solver.result) << s.solver.failure;
  EXPECT_EQ(s.solver.solved_pair_ids.size(), 3u);  // solved again, by itself
  const Pose without_pair_2 = s.solver.result->cam_from_lidar;
  EXPECT_GT((without_pair_2.matrix() - all_pairs.matrix()).cwiseAbs().maxCoeff(), 1e-9);

  // Looking at another pair is no edit: the undo still takes back the rejection.
  controller.Apply(SelectPair{0});
  controller.Apply(Undo{});
  s = Loaded(controller);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kAccepted);
  ASSERT_TRUE(s.solver.result);
  EXPECT_EQ(s.solver.result->cam_from_lidar.matrix(), all_pairs.matrix());
  EXPECT_EQ(LoadSession(dir / "s.json").pairs[2].status, PairStatus::kAccepted);
  // Nor does it lose the redo.
  controller.Apply(SelectPair{1});
  EXPECT_EQ(controller.GetSnapshot().selected, 1);
  EXPECT_TRUE(controller.GetSnapshot().can_redo);

  controller.Apply(Redo{});
  s = Loaded(controller);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  ASSERT_TRUE(s.solver.result);
  EXPECT_EQ(s.solver.result->cam_from_lidar.matrix(), without_pair_2.matrix());
  EXPECT_FALSE(s.can_redo);
  EXPECT_EQ(LoadSession(dir / "s.json").pairs[2].status, PairStatus::kRejected);
}

TEST(Controller, FewerThanThreePairsSaySoInsteadOfSolving) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_few") / "s.json");
  Loaded(controller);
  controller.Apply(SetPairStatus{0, PairStatus::kRejected});
  controller.Apply(SetPairStatus{1, PairStatus::kRejected});
  controller.Apply(RunSolver{});
  const Snapshot s = Loaded(controller);
  EXPECT_FALSE(s.solver.result);
  EXPECT_NE(s.solver.failure.find("only 2"), std::string::npos) << s.solver.failure;
  EXPECT_TRUE(s.status_is_error);
}

TEST(Controller, EveryEditAutosavesAndTheSessionReopensExactly) {
  const auto dir = test::TempDir("controller_session");
  const auto session_path = dir / "work.session.json";
  Session saved;
  {
    Controller controller;
    controller.OpenDataset(test::UiDataset(), session_path);
    Loaded(controller);
    controller.Apply(SetPairStatus{3, PairStatus::kRejected});
    controller.Apply(SelectPair{1});
    controller.Apply(RunSolver{});
    Loaded(controller);
    ASSERT_TRUE(std::filesystem::exists(session_path));
    saved = LoadSession(session_path);
  }
  EXPECT_EQ(saved.pairs[3].status, PairStatus::kRejected);
  std::vector<std::string> ids;
  for (const PairState& pair : saved.pairs) ids.push_back(pair.id);
  EXPECT_EQ(ViewFromJson(saved.view_json, session_path, ids).selected_pair, "0001");
  ASSERT_TRUE(saved.result);
  Controller reopened;
  reopened.OpenSession(session_path);
  const Snapshot s = Loaded(reopened);
  EXPECT_EQ(s.selected, 1);
  EXPECT_EQ(s.pairs[3].status, PairStatus::kRejected);
  ASSERT_TRUE(s.solver.result);
  EXPECT_TRUE(s.solver.result->cam_from_lidar.isApprox(saved.result->cam_from_lidar, 0));
  EXPECT_TRUE(s.pairs[0].residual);             // recomputed from the planes on load
  EXPECT_EQ(LoadSession(session_path), saved);  // reopening rewrote nothing
}

// Every edit goes to the job's record first (its file is the autosave): the rejection, the
// solver's settings, a brush painted over a detected board. Undoing the brush shows the detected
// board again, detected again, as before the edit.
TEST(Controller, EachEditIsInTheJobsRecordAndUndoingABrushDetectsTheBoardAgain) {
  const auto dir = test::TempDir("controller_record_first");
  SimOptions sim = SimPreset("demo");
  sim.num_pairs = 4;
  sim.seed = 3;
  sim.lidar_seeds = false;  // every board found by detection
  const std::filesystem::path manifest = SimulateDataset(sim, dir / "data").manifest;
  const auto session_path = dir / "s.json";
  Controller controller;
  controller.OpenDataset(manifest, session_path);
  const Snapshot detected = Loaded(controller);
  ASSERT_TRUE(detected.pairs[1].lidar) << detected.pairs[1].lidar_failure;
  EXPECT_EQ(detected.pairs[1].board_origin.source, BoardSource::kDetected);
  EXPECT_EQ(detected.pairs[1].brush_origin, BrushOrigin::kDetected);
  ASSERT_FALSE(detected.pairs[1].brush_pixels.empty());

  controller.Apply(SetPairStatus{2, PairStatus::kRejected});
  Loaded(controller);
  EXPECT_EQ(LoadSession(session_path).pairs[2].status, PairStatus::kRejected);
  EXPECT_EQ(LoadSession(session_path).pairs[2].reason, kRejectedByUser);

  JobSettings settings = LoadSession(session_path).settings;
  settings.huber_delta = 0.25;
  settings.max_iterations = 17;
  settings.method = SolverMethod::kWeightedMl;
  settings.estimate_range_offset = true;
  controller.Apply(SetSettings{settings});
  Loaded(controller);
  Session saved = LoadSession(session_path);
  EXPECT_EQ(saved.settings.huber_delta, 0.25);
  EXPECT_EQ(saved.settings.max_iterations, 17);
  EXPECT_TRUE(saved.settings.estimate_range_offset);

  // Erase a disc of the detected board: the record holds the brush the pair now shows.
  const int columns = detected.pairs[1].lidar_image->columns;
  const int pixel = detected.pairs[1].brush_pixels[detected.pairs[1].brush_pixels.size() / 2];
  controller.Apply(BrushStroke{1, pixel / columns, pixel % columns, 4.0f, true});
  controller.Apply(EndStroke{});
  const Snapshot painted = Loaded(controller);
  EXPECT_EQ(painted.pairs[1].brush_origin, BrushOrigin::kPainted);
  EXPECT_LT(painted.pairs[1].brush_pixels.size(), detected.pairs[1].brush_pixels.size());
  saved = LoadSession(session_path);
  ASSERT_TRUE(saved.pairs[1].brush);
  EXPECT_FALSE(saved.pairs[1].brush_from_seed);
  EXPECT_EQ(saved.pairs[1].brush->pixels, painted.pairs[1].brush_pixels);
  EXPECT_EQ(painted.pairs[1].board_origin.source, BoardSource::kBrush);  // refitted from it

  controller.Apply(Undo{});  // the brush
  const Snapshot undone = Loaded(controller);
  EXPECT_NE(undone.pairs[1].brush_origin, BrushOrigin::kPainted);
  EXPECT_EQ(undone.pairs[1].brush_origin, BrushOrigin::kDetected);
  EXPECT_EQ(undone.pairs[1].brush_pixels, detected.pairs[1].brush_pixels);
  ASSERT_TRUE(undone.pairs[1].lidar);
  EXPECT_EQ(undone.pairs[1].board_origin.source, BoardSource::kDetected);
  EXPECT_EQ(undone.pairs[1].lidar->inliers, detected.pairs[1].lidar->inliers);
  EXPECT_FALSE(LoadSession(session_path).pairs[1].brush);
  controller.Apply(Undo{});  // the solver's settings
  EXPECT_EQ(Loaded(controller).settings.max_iterations, SolverOptions{}.max_iterations);
  EXPECT_EQ(LoadSession(session_path).settings.max_iterations, SolverOptions{}.max_iterations);
  controller.Apply(Undo{});  // the rejection
  EXPECT_EQ(Loaded(controller).pairs[2].status, PairStatus::kAccepted);
  EXPECT_NE(LoadSession(session_path).pairs[2].status, PairStatus::kRejected);
}

// A relative export or save-as path goes next to the session, never into the folder the program
// was started from.
TEST(Controller, RelativeExportAndSaveAsPathsGoNextToTheSession) {
  const auto dir = test::TempDir("controller_export_place");
  const auto session_path = dir / "work.session.json";
  Controller controller;
  controller.OpenDataset(test::UiDataset(), session_path);
  Loaded(controller);
  controller.Apply(RunSolver{});
  Loaded(controller);
  const auto start_dir = std::filesystem::current_path();
  std::filesystem::remove(start_dir / "exported_here.json");
  controller.Apply(ExportResult{"exported_here.json"});
  EXPECT_TRUE(std::filesystem::exists(dir / "exported_here.json"));
  EXPECT_FALSE(std::filesystem::exists(start_dir / "exported_here.json"));
  EXPECT_NE(controller.GetSnapshot().status_line.find((dir / "exported_here.json").string()),
            std::string::npos);
  controller.Apply(SaveSessionAs{"copy.session.json"});
  EXPECT_TRUE(std::filesystem::exists(dir / "copy.session.json"));
  EXPECT_EQ(controller.GetSnapshot().session_path, dir / "copy.session.json");
}

// A session whose brush was painted on another LiDAR image layout: that brush is refused with a
// message naming the cloud and both layouts, the pair falls back to its seed, and the rest of
// the session (another pair's brush, a rejection) loads as saved.
TEST(Controller, ABrushOfTheWrongSizeIsDroppedWithAMessageAndTheRestLoads) {
  const auto dir = test::TempDir("controller_wrong_brush");
  const auto session_path = dir / "work.session.json";
  std::vector<int> good_brush;
  {
    Controller controller;
    controller.OpenDataset(test::UiDataset(), session_path);
    const Snapshot s = Loaded(controller);
    good_brush = s.pairs[1].brush_pixels;  // the seed's region, painted over as the user's
    controller.Apply(PaintPoints{1, good_brush, false});
    controller.Apply(EndStroke{});
    controller.Apply(SetPairStatus{3, PairStatus::kRejected});
    Loaded(controller);
  }
  Session session = LoadSession(session_path);
  ASSERT_TRUE(session.pairs[1].brush);
  session.pairs[0].brush = BrushMask{3, 3, {0, 4, 8}};  // painted on a 3x3 image
  session.pairs[0].brush_from_seed = false;
  SaveSession(session_path, session);

  Controller reopened;
  reopened.OpenSession(session_path);
  const Snapshot s = Loaded(reopened);
  EXPECT_NE(s.status_line.find("painted on a 3x3 LiDAR image"), std::string::npos) << s.status_line;
  EXPECT_NE(s.status_line.find("its brush from the session was dropped"), std::string::npos)
      << s.status_line;
  EXPECT_TRUE(s.status_is_error);
  EXPECT_TRUE(s.pairs[0].lidar);  // back on its seed
  EXPECT_EQ(s.pairs[0].brush_origin, BrushOrigin::kSeeded);
  EXPECT_EQ(s.pairs[1].brush_pixels, session.pairs[1].brush->pixels);
  EXPECT_EQ(s.pairs[3].status, PairStatus::kRejected);
}

// Opening a dataset whose folder holds a session, as the window does: the session resumes (a
// rejected pair stays rejected, the result stays) and the status line says so; --fresh moves it
// to a timestamped backup first; a session that does not open is backed up, never overwritten.
TEST(Controller, ReopeningADatasetResumesItsSessionOrBacksItUp) {
  const auto dir = test::TempDir("controller_resume");
  const auto session_path = dir / "calibench.session.json";
  using Existing = ExistingSession;
  {
    Controller controller;
    controller.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
    Loaded(controller);
    controller.Apply(SetPairStatus{3, PairStatus::kRejected});
    controller.Apply(RunSolver{});
    Loaded(controller);
  }
  const std::string saved = test::ReadFileBytes(session_path);
  auto backups = [&] {
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      if (entry.path().extension() == ".bak") found.push_back(entry.path());
    return found;
  };
  {
    Controller resumed;
    resumed.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
    const Snapshot s = Loaded(resumed);
    EXPECT_EQ(s.pairs[3].status, PairStatus::kRejected);
    EXPECT_TRUE(s.solver.result);
    EXPECT_NE(s.status_line.find("resumed the session in " + session_path.string()),
              std::string::npos)
        << s.status_line;
    EXPECT_EQ(test::ReadFileBytes(session_path), saved);
  }
  {
    Controller fresh;
    fresh.OpenDataset(test::UiDataset(), session_path, Existing::kStartFresh);
    const Snapshot s = Loaded(fresh);
    EXPECT_EQ(s.pairs[3].status, PairStatus::kAccepted);
    ASSERT_EQ(backups().size(), 1u);
    EXPECT_EQ(test::ReadFileBytes(backups()[0]), saved);
    EXPECT_NE(s.status_line.find("kept the old session as " + backups()[0].string()),
              std::string::npos)
        << s.status_line;
  }
  const std::string corrupt = "{\"format\": \"calibench.session.v1\", \"pairs\": [";
  std::ofstream(session_path) << corrupt;
  Controller after_corrupt;
  after_corrupt.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
  const Snapshot s = Loaded(after_corrupt);
  EXPECT_NE(s.status_line.find("did not open"), std::string::npos) << s.status_line;
  ASSERT_EQ(backups().size(), 2u);
  int corrupt_backups = 0;
  for (const auto& backup : backups()) corrupt_backups += test::ReadFileBytes(backup) == corrupt;
  EXPECT_EQ(corrupt_backups, 1);
}

// An autosave that cannot be written (here: its folder is gone) is shown on the status line, for
// edits and for undo alike, and the edit itself stands.
TEST(Controller, AFailedAutosaveIsShownAndTheEditStands) {
  const auto dir = test::TempDir("controller_autosave_fails");
  const auto session_path = dir / "gone" / "work.session.json";
  Controller controller;
  controller.OpenDataset(test::UiDataset(), session_path);
  Loaded(controller);
  controller.Apply(SetPairStatus{2, PairStatus::kRejected});
  Snapshot s = controller.GetSnapshot();
  EXPECT_EQ(s.pairs[2].status, PairStatus::kRejected);
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find("autosave failed: " + session_path.string()), std::string::npos)
      << s.status_line;
  EXPECT_NE(s.save_error.find(session_path.string()), std::string::npos) << s.save_error;
  controller.Apply(Undo{});  // must not throw out of Apply
  s = Loaded(controller);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kAccepted);
  EXPECT_NE(s.status_line.find("autosave failed"), std::string::npos) << s.status_line;
}

TEST(Controller, ACorruptSessionIsReportedAndLeftUntouched) {
  const auto path = test::TempDir("controller_corrupt") / "broken.session.json";
  const std::string text = "{\"format\": \"calibench.session.v1\", \"version\": 1, \"pairs\": [";
  std::ofstream(path) << text;
  Controller controller;
  try {
    controller.OpenSession(path);
    FAIL() << "a corrupt session must not open";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.session.json"), std::string::npos) << e.what();
  }
  std::ifstream in(path);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), {}), text);
}

// A session whose file no longer opens is resumed from its newest autosave backup that does.
TEST(Controller, AnUnreadableSessionIsResumedFromItsNewestBackup) {
  const auto dir = test::TempDir("controller_resume_backup");
  const auto session_path = dir / "calibench.session.json";
  using Existing = ExistingSession;
  for (int pair : {3, 2}) {  // two sittings: the second's first save backs up the first's file
    Controller controller;
    controller.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
    Loaded(controller);
    controller.Apply(SetPairStatus{pair, PairStatus::kRejected});
    Loaded(controller);
  }
  ASSERT_TRUE(std::filesystem::exists(SessionBackupPath(session_path, 1)));
  std::ofstream(session_path, std::ios::trunc) << "{\"format\": \"calibench.session.v1\", \"pai";
  Controller controller;
  controller.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
  const Snapshot s = Loaded(controller);
  EXPECT_EQ(s.pairs[3].status, PairStatus::kRejected);
  EXPECT_EQ(s.pairs[2].status, PairStatus::kAccepted);  // the newest backup predates that edit
  EXPECT_NE(s.status_line.find("resumed its newest backup that opens, " +
                               SessionBackupPath(session_path, 1).string()),
            std::string::npos)
      << s.status_line;
}

// Two workbenches never edit one session: the second is refused, naming the first.
TEST(Controller, ASecondWorkbenchOnTheSameSessionIsRefused) {
  const auto session_path = test::TempDir("controller_lock") / "calibench.session.json";
  using Existing = ExistingSession;
  auto first = std::make_unique<Controller>();
  first->OpenDataset(test::UiDataset(), session_path, Existing::kResume);
  Loaded(*first);
  Controller second;
  try {
    second.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
    FAIL() << "a session open in another workbench must not open again";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("open in another Calibench workbench (pid " +
                                         std::to_string(getpid())),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(second.OpenSession(session_path), IoError);
  first->OpenDataset(test::UiDataset(), session_path, Existing::kResume);  // its own: fine
  Loaded(*first);
  first.reset();
  second.OpenDataset(test::UiDataset(), session_path, Existing::kResume);
  EXPECT_EQ(Loaded(second).session_path, session_path);
}

// kInMemory (render) neither reads nor writes nor locks the session file it is pointed at.
TEST(Controller, AnInMemorySessionLeavesTheSessionFileAlone) {
  const auto dir = test::TempDir("controller_in_memory");
  const auto session_path = dir / "calibench.session.json";
  std::ofstream(session_path) << "an hour of someone's work";
  Controller controller;
  controller.OpenDataset(test::UiDataset(), session_path, ExistingSession::kInMemory);
  Loaded(controller);
  controller.Apply(SetPairStatus{1, PairStatus::kRejected});
  controller.Apply(RunSolver{});
  const Snapshot s = Loaded(controller);
  EXPECT_TRUE(s.solver.result);
  EXPECT_TRUE(s.session_path.empty());
  EXPECT_TRUE(s.save_error.empty());
  EXPECT_EQ(test::ReadFileBytes(session_path), "an hour of someone's work");
  EXPECT_FALSE(std::filesystem::exists(LockPathOf(session_path)));
}

// Makes a folder read-only for this process: chmod, and for root (whom chmod does not stop) the
// immutable attribute; undone when it goes out of scope. readonly() is false where neither works.
class ReadOnlyFolder {
 public:
  explicit ReadOnlyFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_write,
                                 std::filesystem::perm_options::remove);
    if (!Writable()) return;
    immutable_ = test::RunCommand("chattr +i '" + dir_.string() + "'") == 0;
  }
  ~ReadOnlyFolder() {
    if (immutable_) test::RunCommand("chattr -i '" + dir_.string() + "'");
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_write,
                                 std::filesystem::perm_options::add);
  }
  bool readonly() const { return !Writable(); }

 private:
  bool Writable() const { return ::access(dir_.c_str(), W_OK) == 0 && !immutable_; }
  std::filesystem::path dir_;
  bool immutable_ = false;
};

// A dataset in a read-only folder (a colleague's share, a mounted recording): it opens, edits
// work, and every save that cannot happen is said on the status line in the warning colour.
TEST(Controller, AReadOnlyDatasetFolderOpensAndSaysItCannotSave) {
  const auto dir = test::TempDir("controller_read_only");
  const Dataset dataset = LoadDataset(test::UiDataset());
  SaveDataset(dir / "dataset.json", dataset);  // absolute paths to the clouds and images
  ReadOnlyFolder read_only(dir);
  if (!read_only.readonly()) GTEST_SKIP() << "cannot make a folder read-only here";
  Controller controller;
  controller.OpenDataset(dir / "dataset.json", {}, ExistingSession::kResume);
  Snapshot s = Loaded(controller);
  // Loading already saves (the detected boards): the status line says at once that it cannot.
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find((dir / "calibench.session.json").string()), std::string::npos)
      << s.status_line;
  controller.Apply(SetPairStatus{1, PairStatus::kRejected});
  s = controller.GetSnapshot();
  EXPECT_EQ(s.pairs[1].status, PairStatus::kRejected);
  EXPECT_TRUE(s.status_is_error);
  EXPECT_NE(s.status_line.find("autosave failed: " + (dir / "calibench.session.json").string()),
            std::string::npos)
      << s.status_line;
  EXPECT_FALSE(s.save_error.empty());
  EXPECT_FALSE(std::filesystem::exists(dir / "calibench.session.json"));
}

}  // namespace
}  // namespace calibench::ui

namespace calibench::ui {
namespace {

// The meter after a solve is the stop rule's verdict (as `advise` judges) on the workbench's
// result: σ per axis from its covariance, the weakest axis against an editable goal, not done
// with fewer pairs than the rule trusts; one history point per solve at a number of pairs.
TEST(Controller, TheMeterJudgesTheSolveAgainstTheGoal) {
  Controller controller;
  controller.OpenDataset(test::UiDataset(), test::TempDir("controller_meter") / "s.json");
  controller.WaitIdle();
  EXPECT_FALSE(controller.GetSnapshot().meter);
  controller.Apply(RunSolver{});
  Snapshot s = Loaded(controller);
  ASSERT_TRUE(s.solver.result && s.meter);
  const CaptureState expected = JudgeCapture(*s.solver.result, 4, CaptureGoal{}, StopRuleOptions{});
  EXPECT_EQ(s.meter->sigma_t_mm, expected.sigma_t_mm);
  EXPECT_EQ(s.meter->sigma_r_deg, expected.sigma_r_deg);
  EXPECT_EQ(s.meter->pairs_used, 4);
  EXPECT_FALSE(s.meter->done);  // four pairs: the σ is not trusted yet
  EXPECT_FALSE(s.meter->trustworthy);
  ASSERT_EQ(s.meter_history.size(), 1u);
  EXPECT_EQ(s.meter_history[0].pairs, 4);
  // A goal no σ meets: the weakest axis named; a loose one: met (still not done: four pairs).
  controller.Apply(SetGoal{CaptureGoal{0.001, 0.0001}});
  s = Loaded(controller);
  EXPECT_FALSE(s.meter->goal_met);
  EXPECT_FALSE(s.meter->weakest.empty());
  controller.Apply(SetGoal{CaptureGoal{100.0, 10.0}});
  s = Loaded(controller);
  EXPECT_TRUE(s.meter->goal_met);
  EXPECT_FALSE(s.meter->done);
  // A bad goal is refused in words, the old one kept.
  controller.Apply(SetGoal{CaptureGoal{-1.0, 0.1}});
  s = Loaded(controller);
  EXPECT_TRUE(s.status_is_error);
  EXPECT_EQ(s.goal.translation_mm, 100.0);
  // Solving again at the same number of pairs replaces the point; one fewer pair adds one. (A
  // solve reads the pairs when the worker runs it: the first is waited for before the rejection,
  // or on a loaded machine both would see three pairs.)
  controller.Apply(RunSolver{});
  s = Loaded(controller);
  controller.Apply(SetPairStatus{0, PairStatus::kRejected});
  controller.Apply(RunSolver{});
  s = Loaded(controller);
  ASSERT_EQ(s.meter_history.size(), 2u);
  EXPECT_EQ(s.meter_history[1].pairs, 3);
}

}  // namespace
}  // namespace calibench::ui
