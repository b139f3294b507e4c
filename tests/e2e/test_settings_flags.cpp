// The solver settings' flags are made from their one declaration (JobSettingFields,
// core/session/session.h): every setting is a flag of each command that runs the pipeline, its
// value lands in the settings the session and the job keep, and a flag's choice the solver would
// refuse is refused, not dropped.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <string>

#include "app/pipeline_flags.h"
#include "core/session/session.h"

namespace calibench::app {
namespace {

TEST(SettingsFlags, EverySettingIsAFlagAndLandsInTheJobsSettings) {
  CLI::App app;
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  for (const JobSettingField& setting : JobSettingFields())
    EXPECT_NO_THROW(app.get_option("--" + std::string(setting.flag))) << setting.flag;
  // Unset, they are the settings' defaults.
  {
    CLI::App defaults_app;
    PipelineFlags defaults;
    AddPipelineFlags(defaults_app, defaults);
    defaults_app.parse(std::string(), false);
    std::string why;
    ASSERT_TRUE(FinalizePipelineFlags(defaults, &why)) << why;
    EXPECT_EQ(JobSettings::Of(defaults.options), JobSettings{});
  }

  app.parse(
      "--method weighted-ml --huber-delta 0.25 --max-iterations 7 --estimate-range-offset "
      "--ransac-threshold 0.03",
      false);
  std::string why;
  ASSERT_TRUE(FinalizePipelineFlags(flags, &why)) << why;
  JobSettings expected;
  expected.method = SolverMethod::kWeightedMl;
  expected.huber_delta = 0.25;
  expected.max_iterations = 7;
  expected.estimate_range_offset = true;
  expected.ransac_threshold_m = 0.03;
  EXPECT_EQ(JobSettings::Of(flags.options), expected);
  EXPECT_EQ(flags.options.solver.huber_delta, 0.25);
  EXPECT_EQ(flags.options.lidar_plane.ransac_threshold_m, 0.03);

  CLI::App kim_app;
  PipelineFlags kim;
  AddPipelineFlags(kim_app, kim);
  kim_app.parse("--method kim --max-iterations 3", false);
  ASSERT_TRUE(FinalizePipelineFlags(kim, &why)) << why;
  EXPECT_EQ(kim.options.solver.method, SolverMethod::kKim);
  EXPECT_EQ(kim.options.solver.max_iterations, 3);
}

TEST(SettingsFlags, ARangeOffsetAskedOfAnotherMethodIsRefusedNotDropped) {
  CLI::App app;
  PipelineFlags flags;
  AddPipelineFlags(app, flags);
  app.parse("--method ca2lib-gn --estimate-range-offset", false);
  std::string why;
  EXPECT_FALSE(FinalizePipelineFlags(flags, &why));
  EXPECT_NE(why.find("weighted-ml method only"), std::string::npos) << why;

  CLI::App bad_app;
  PipelineFlags bad;
  AddPipelineFlags(bad_app, bad);
  bad_app.parse("--method newton", false);
  EXPECT_FALSE(FinalizePipelineFlags(bad, &why));
  EXPECT_NE(why.find("--method must be weighted-ml, ca2lib-gn or kim, not 'newton'"),
            std::string::npos)
      << why;
}

}  // namespace
}  // namespace calibench::app
