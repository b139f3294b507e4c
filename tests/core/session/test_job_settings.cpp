// The solver's settings declared once (JobSettingFields, core/session/session.h): every setting
// goes to and from the pipeline's options and the session file through that table, and sessions
// written before a later setting existed keep its default.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "core/base/types.h"
#include "core/session/session.h"

namespace calibench {
namespace {

// Every setting away from its default, so that a setting the table forgets shows.
JobSettings Unusual() {
  JobSettings settings;
  settings.method = SolverMethod::kCa2libGn;
  settings.huber_delta = 0.037;
  settings.max_iterations = 13;
  settings.estimate_range_offset = true;
  settings.ransac_threshold_m = 0.031;
  return settings;
}

TEST(JobSettingsTable, EverySettingGoesToThePipelineAndBackThroughTheTable) {
  const JobSettings settings = Unusual();
  ASSERT_NE(settings, JobSettings{});
  PipelineOptions options;
  settings.Apply(&options);
  EXPECT_EQ(options.solver.method, SolverMethod::kCa2libGn);
  EXPECT_EQ(options.solver.huber_delta, 0.037);
  EXPECT_EQ(options.solver.max_iterations, 13);
  EXPECT_EQ(options.lidar_plane.ransac_threshold_m, 0.031);
  // The one derived rule: only the weighted method estimates a range offset; the choice stays.
  EXPECT_FALSE(options.solver.estimate_range_offset);
  JobSettings weighted = settings;
  weighted.method = SolverMethod::kWeightedMl;
  EXPECT_TRUE(weighted.Over(options).solver.estimate_range_offset);
  EXPECT_EQ(JobSettings::Of(weighted.Over(PipelineOptions{})), weighted);
  // Keys are unique, flags are unique, and the file's keys are the ones sessions have always had.
  std::set<std::string> keys, flags;
  for (const JobSettingField& field : JobSettingFields()) {
    EXPECT_TRUE(keys.insert(field.Key()).second) << field.Key();
    EXPECT_TRUE(flags.insert(std::string(field.flag)).second) << field.flag;
  }
  EXPECT_EQ(keys, (std::set<std::string>{"method", "huber_delta", "max_iterations",
                                         "estimate_range_offset", "ransac_threshold_m"}));
}

TEST(JobSettingsTable, TheSessionFileKeepsEverySettingAndOldFilesTheirDefaults) {
  Session session;
  session.dataset = "/data/dataset.json";
  session.settings = Unusual();
  const std::string text = SessionToJson(session, "/data/s.json");
  const nlohmann::json options = nlohmann::json::parse(text).at("options");
  EXPECT_EQ(options.at("method"), "ca2lib-gn");
  EXPECT_EQ(options.at("huber_delta"), 0.037);
  EXPECT_EQ(options.at("max_iterations"), 13);
  EXPECT_EQ(options.at("estimate_range_offset"), true);
  EXPECT_EQ(options.at("ransac_threshold_m"), 0.031);
  EXPECT_EQ(SessionFromJson(text, "/data/s.json").settings, session.settings);

  // A session written before the method and the range offset were settings.
  nlohmann::json old = nlohmann::json::parse(text);
  old["options"].erase("method");
  old["options"].erase("estimate_range_offset");
  const JobSettings read = SessionFromJson(old.dump(), "/data/s.json").settings;
  EXPECT_EQ(read.method, JobSettings{}.method);
  EXPECT_FALSE(read.estimate_range_offset);
  EXPECT_EQ(read.huber_delta, 0.037);

  // The others are required, and each is checked by its kind, naming the key.
  auto refused = [&](const char* key, const nlohmann::json& value, const std::string& problem) {
    nlohmann::json broken = nlohmann::json::parse(text);
    if (value.is_null())
      broken["options"].erase(key);
    else
      broken["options"][key] = value;
    try {
      SessionFromJson(broken.dump(), "/data/s.json");
      ADD_FAILURE() << key << " = " << value.dump() << " was read";
    } catch (const IoError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("options.") + key), std::string::npos) << message;
      EXPECT_NE(message.find(problem), std::string::npos) << message;
    }
  };
  refused("huber_delta", nullptr, "missing");
  refused("huber_delta", 0.0, "");
  refused("ransac_threshold_m", -0.01, "");
  refused("max_iterations", 0, "must be at least 1");
  refused("method", "newton", "is not weighted-ml, ca2lib-gn or kim");
  refused("estimate_range_offset", "yes", "");
}

}  // namespace
}  // namespace calibench
