// The report's views drawn from the outcome already solved (ui/lidar_camera/report_figures.h):
// the snapshot made from the outcome is the one the workbench's controller shows after the same
// solve, each pair's figure shows its LiDAR points over its image, and a pair whose files went
// missing loses its view, named, not the report.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/io/dataset.h"
#include "core/io/image_io.h"
#include "tests/test_support.h"
#include "tests/ui/golden.h"
#include "tests/ui/ui_fixture.h"
#include "ui/lidar_camera/controller_outcome.h"
#include "ui/lidar_camera/report_figures.h"

namespace calibench::ui {
namespace {

namespace fs = std::filesystem;

// Coloured pixels (the reprojected points are coloured by depth, the simulated room and board are
// grey): the points, the detected corners and the board's outline and axes.
int ColouredPixels(const ImageU8& picture) {
  int count = 0;
  for (int i = 0; i < picture.width * picture.height; ++i) {
    const std::uint8_t* bgr = &picture.data[static_cast<size_t>(i) * picture.channels];
    if (std::max({bgr[0], bgr[1], bgr[2]}) - std::min({bgr[0], bgr[1], bgr[2]}) > 50) ++count;
  }
  return count;
}

ImageU8 Decoded(const ReportFigure& figure, const fs::path& dir) {
  const fs::path file = dir / (figure.pair_id.empty() ? "overview.png" : figure.pair_id + ".jpg");
  WriteFileAtomically(file, figure.bytes);
  return LoadImage(file);
}

TEST(ReportFigures, DrawnFromTheOutcomeAsTheWorkbenchShowsIt) {
  if (!HeadlessOrSkip()) GTEST_SKIP() << "no headless OpenGL (EGL or OSMesa) on this machine";
  const fs::path dir = test::TempDir("report_figures");
  fs::remove_all(dir / "data");
  fs::copy(test::UiDataset().parent_path(), dir / "data", fs::copy_options::recursive);
  const fs::path manifest = dir / "data" / test::UiDataset().filename();
  const Dataset dataset = LoadDataset(manifest);
  const CalibrationOutcome outcome = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(outcome.solution) << outcome.failure;

  // The workbench's controller after the same solve: the same pose, pairs and reprojection.
  Controller controller;
  controller.OpenDataset(manifest, dir / "session.json");
  controller.WaitIdle();
  controller.Apply(RunSolver{});
  const Snapshot workbench = Loaded(controller);
  const Snapshot solved = SnapshotOfOutcome(dataset, outcome);
  ASSERT_TRUE(workbench.solver.result && solved.solver.result);
  EXPECT_TRUE(solved.solver.result->cam_from_lidar.matrix().isApprox(
      workbench.solver.result->cam_from_lidar.matrix(), 1e-9));
  EXPECT_EQ(solved.solver.solved_pair_ids, workbench.solver.solved_pair_ids);
  ASSERT_EQ(solved.pairs.size(), workbench.pairs.size());
  for (size_t i = 0; i < solved.pairs.size(); ++i) {
    EXPECT_EQ(solved.pairs[i].id, workbench.pairs[i].id);
    EXPECT_EQ(solved.pairs[i].status, workbench.pairs[i].status);
    ASSERT_EQ(solved.pairs[i].residual.has_value(), workbench.pairs[i].residual.has_value());
    if (solved.pairs[i].residual) {
      EXPECT_LT((*solved.pairs[i].residual - *workbench.pairs[i].residual).norm(), 1e-9);
    }
  }
  ASSERT_GE(workbench.selected, 0);
  std::string why;
  const auto pair = LoadOutcomePair(solved, workbench.selected, nullptr, &why);
  ASSERT_TRUE(pair && pair->reprojection) << why;
  ASSERT_TRUE(workbench.reprojection);
  EXPECT_EQ(pair->reprojection->visible, workbench.reprojection->visible);
  EXPECT_EQ(pair->reprojection->points.size(), workbench.reprojection->points.size());

  // Every pair's figure, and the overview; the points drawn over the image.
  const std::vector<ReportFigure> figures =
      DrawReportFigures(dataset, outcome, ReportFigureOptions{}, nullptr, &why);
  EXPECT_EQ(why, "");
  ASSERT_EQ(figures.size(), dataset.pairs.size() + 1);
  EXPECT_EQ(figures[0].pair_id, "");
  EXPECT_EQ(figures[0].mime, "image/png");
  const ImageU8 overview = Decoded(figures[0], dir);
  EXPECT_EQ(overview.width, 1200);
  EXPECT_EQ(overview.height, 560);
  std::vector<int> coloured;
  for (size_t i = 1; i < figures.size(); ++i) {
    EXPECT_EQ(figures[i].pair_id, dataset.pairs[i - 1].id);
    const ImageU8 picture = Decoded(figures[i], dir);
    EXPECT_EQ(picture.width, 640);
    EXPECT_EQ(picture.height, 480);
    coloured.push_back(ColouredPixels(picture));
  }

  // Without a solution the same views carry no points: only the corners and the board's outline
  // stay coloured.
  CalibrationOutcome unsolved = outcome;
  unsolved.solution.reset();
  unsolved.failure = "test: no solution";
  const std::vector<ReportFigure> bare =
      DrawReportFigures(dataset, unsolved, ReportFigureOptions{}, nullptr, &why);
  ASSERT_EQ(bare.size(), figures.size());
  for (size_t i = 1; i < bare.size(); ++i) {
    const int without = ColouredPixels(Decoded(bare[i], dir));
    EXPECT_GT(coloured[i - 1], without + 10000) << bare[i].pair_id << ": " << without;
  }

  // The pairs' files kept as the extraction read them give the same pictures, byte for byte; so
  // do two kept and the rest read again (the memory bound).
  for (const int max_pairs : {64, 2}) {
    KeptPairInputs kept(dataset.camera, ReportFigureOptions{}, max_pairs);
    PipelineOptions keeping;
    keeping.on_pair_inputs = kept.Keeper();
    ASSERT_TRUE(CalibrateDataset(dataset, keeping).solution);
    int held = 0;
    for (const PairEntry& entry : dataset.pairs) held += kept.Find(entry.id).has_value();
    EXPECT_EQ(held, std::min<int>(max_pairs, dataset.pairs.size()));
    const std::vector<ReportFigure> from_kept =
        DrawReportFigures(dataset, outcome, ReportFigureOptions{}, &kept, &why);
    ASSERT_EQ(from_kept.size(), figures.size());
    for (size_t i = 0; i < figures.size(); ++i)
      EXPECT_TRUE(from_kept[i].bytes == figures[i].bytes)
          << figures[i].pair_id << ", " << max_pairs;
  }

  // A pair whose image went missing after the solve: its view is left out and named.
  const fs::path missing = dataset.pairs[1].image;
  fs::remove(missing);
  why.clear();
  const std::vector<ReportFigure> fewer =
      DrawReportFigures(dataset, outcome, ReportFigureOptions{}, nullptr, &why);
  EXPECT_EQ(fewer.size(), figures.size() - 1);
  EXPECT_NE(why.find("1 pair(s) without a view"), std::string::npos) << why;
  EXPECT_NE(why.find(missing.filename().string()), std::string::npos) << why;
}

}  // namespace
}  // namespace calibench::ui
