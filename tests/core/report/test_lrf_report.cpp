// The 2D LRF report (core/report/lrf_report.h): per observation the target's residual as the
// solver states it, leave-one-out influence and held-out residual, a verdict that names the one
// observation made wrong and no other, and the page's sections.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/lrf/pipeline.h"
#include "core/report/lrf_report.h"
#include "core/sim/lrf_sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

struct Solved {
  LrfDataset dataset;
  LrfCalibrationOutcome outcome;
};

Solved SimulatedSolve(const std::string& name) {
  LrfSimOptions sim = *LrfSimPreset("paper");
  sim.observations = 10;
  sim.seed = 3;
  Solved solved{LoadLrfDataset(WriteLrfSimDataset(sim, test::TempDir(name))), {}};
  solved.outcome = CalibrateLrfDataset(solved.dataset, LrfPipelineOptions{});
  CALIBENCH_CHECK(solved.outcome.solution.has_value());
  return solved;
}

ReportAssets Assets() {
  return LoadReportAssets(std::filesystem::path(CALIBENCH_SOURCE_DIR) / "assets/report");
}

TEST(LrfReport, ResidualsAreTheSolversAndACleanSetIsConsistent) {
  const Solved solved = SimulatedSolve("lrf_report_clean");
  const LrfSolution& s = *solved.outcome.solution;
  const LrfReport report =
      AnalyseLrfCalibration(solved.dataset, solved.outcome, LrfPipelineOptions{});
  ASSERT_EQ(report.pairs.size(), solved.outcome.pairs.size());
  int compared = 0;
  for (size_t i = 0; i < report.pairs.size(); ++i) {
    const LrfPairReportRow& row = report.pairs[i];
    if (!row.solved) continue;
    // Eq. (12) as the solver computed it for the result.
    ASSERT_TRUE(row.residual_mm) << row.id;
    EXPECT_NEAR(*row.residual_mm, 1e3 * s.point_to_line_m[i], 1e-9) << row.id;
    ASSERT_TRUE(row.heldout_mm && row.influence_mm && row.influence_deg) << row.id;
    // Ten observations at the paper's noise: leaving one out moves the result by millimetres.
    EXPECT_LT(*row.influence_mm, 15.0) << row.id;
    EXPECT_LT(*row.influence_deg, 0.5) << row.id;
    EXPECT_FALSE(row.disagrees) << row.id;
    EXPECT_NE(row.svg.find("<svg"), std::string::npos) << row.id;
    ++compared;
  }
  EXPECT_GE(compared, 8);
  EXPECT_EQ(report.folds, compared);
  EXPECT_TRUE(report.well_constrained);
  // Predicting an observation it has not seen, the solve does no better than on those it has.
  EXPECT_GE(report.heldout_rms_mm, report.train_rms_mm);
  EXPECT_EQ(report.verdict.rfind("consistent", 0), 0u) << report.verdict;
  ReportProvenance provenance;
  provenance.source = solved.dataset.manifest.string();
  const std::string html = LrfReportHtml(report, provenance, Assets());
  for (const char* part : {"cam_from_lrf", "lrf_from_cam", "Verdict: consistent", "lrf-residuals",
                           "id=\"pairs\"", "id=\"views\"", "\"kind\":\"lrf\""})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  EXPECT_EQ(html.find("Not well constrained"), std::string::npos);
}

// The depth camera's view of one observation moved 4 cm sideways (a target bumped between the
// scan and the depth frame): the report names that observation, and no other.
TEST(LrfReport, AnObservationMadeWrongIsTheOneThatDisagrees) {
  const Solved solved = SimulatedSolve("lrf_report_bumped");
  std::vector<LrfPairFeatures> pairs = solved.outcome.pairs;
  size_t bumped = pairs.size();
  for (size_t i = 0; i < pairs.size() && bumped == pairs.size(); ++i)
    if (pairs[i].status == PairStatus::kAccepted && pairs[i].three_face) bumped = i;
  ASSERT_LT(bumped, pairs.size());
  DepthFeatures& depth = pairs[bumped].three_face->depth;
  const Vec3 moved(0.04, 0.0, 0.0);  // camera x, metres
  for (Plane& plane : depth.planes) plane.distance -= plane.normal.dot(moved);
  for (Line3& line : depth.lines) line.point += moved;
  const LrfCalibrationOutcome outcome =
      SolveLrfFromFeatures(std::move(pairs), solved.dataset, LrfPipelineOptions{});
  ASSERT_TRUE(outcome.solution) << outcome.failure;
  const LrfReport report = AnalyseLrfCalibration(solved.dataset, outcome, LrfPipelineOptions{});
  for (size_t i = 0; i < report.pairs.size(); ++i)
    EXPECT_EQ(report.pairs[i].disagrees, i == bumped)
        << report.pairs[i].id << ": held out " << report.pairs[i].heldout_mm.value_or(-1) << " mm";
  EXPECT_NE(report.verdict.find("disagreeing: " + report.pairs[bumped].id), std::string::npos)
      << report.verdict;
  std::printf("%s\n", report.verdict.c_str());
}

TEST(LrfReport, WithoutCrossValidationItSaysWhy) {
  const Solved solved = SimulatedSolve("lrf_report_off");
  LrfReportOptions options;
  options.cross_validate = false;
  const LrfReport report =
      AnalyseLrfCalibration(solved.dataset, solved.outcome, LrfPipelineOptions{}, options);
  EXPECT_EQ(report.folds, 0);
  EXPECT_NE(report.cross_validation_skipped.find("switched off"), std::string::npos);
  const std::string html = LrfReportHtml(report, {}, Assets());
  EXPECT_NE(html.find("Not computed: switched off"), std::string::npos);
  LrfCalibrationOutcome unsolved = solved.outcome;
  unsolved.solution.reset();
  EXPECT_THROW(AnalyseLrfCalibration(solved.dataset, unsolved, LrfPipelineOptions{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace calibench
