// assets/: the target presets and the LiDAR presets are the ones the code uses (BoardPreset,
// MakeBeamTable), so a user who copies one to edit it starts from the truth. Regenerate them with
// CALIBENCH_UPDATE_GOLDENS=1 after changing a preset in the code.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/io/assets.h"
#include "core/io/dataset.h"
#include "core/io/json_io.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

bool Updating() {
  const char* update = std::getenv("CALIBENCH_UPDATE_GOLDENS");
  return update && std::string(update) == "1";
}

fs::path SourceAssets() { return fs::path(CALIBENCH_SOURCE_DIR) / "assets"; }

nlohmann::json BeamTableJson(LidarModel model) {
  const BeamTable beams = MakeBeamTable(model);
  nlohmann::json j = {{"name", LidarModelName(model)},
                      {"elevations_deg", nlohmann::json::array()},
                      {"azimuth_steps", beams.azimuth_steps},
                      {"max_range_m", beams.max_range_m},
                      {"swept", beams.swept}};
  for (const double e : beams.elevations_rad) j["elevations_deg"].push_back(e * kRadToDeg);
  if (beams.swept)
    j["mirror_offset_m"] = {beams.mirror_offset_m.x(), beams.mirror_offset_m.y(),
                            beams.mirror_offset_m.z()};
  return j;
}

TEST(Assets, TargetPresetsAreTheCodes) {
  for (const char* name : {"a3", "a4", "charuco-a3", "charuco-a4", "paper"}) {
    const fs::path file = SourceAssets() / "targets" / (std::string(name) + ".json");
    if (Updating())
      WriteFileAtomically(file, json_io::TargetToJson(BoardPreset(name)).dump(2) + "\n");
    const BoardSpec loaded = LoadTargetFile(file);
    const BoardSpec preset = BoardPreset(name);
    EXPECT_EQ(json_io::TargetToJson(loaded), json_io::TargetToJson(preset)) << file;
  }
}

TEST(Assets, LidarPresetsAreTheSimulatorsBeamTables) {
  for (const LidarModel model :
       {LidarModel::kHdl64, LidarModel::kVlp16, LidarModel::kOs0_128, LidarModel::kSwept2d}) {
    const fs::path file = SourceAssets() / "lidars" / (LidarModelName(model) + ".json");
    if (Updating()) WriteFileAtomically(file, BeamTableJson(model).dump(2) + "\n");
    std::ifstream in(file);
    const auto loaded = nlohmann::json::parse(in, nullptr, false);
    ASSERT_FALSE(loaded.is_discarded()) << file;
    const nlohmann::json expected = BeamTableJson(model);
    ASSERT_EQ(loaded["elevations_deg"].size(), expected["elevations_deg"].size()) << file;
    for (size_t i = 0; i < expected["elevations_deg"].size(); ++i)
      EXPECT_NEAR(loaded["elevations_deg"][i].get<double>(),
                  expected["elevations_deg"][i].get<double>(), 1e-9)
          << file << " ring " << i;
    EXPECT_EQ(loaded["azimuth_steps"], expected["azimuth_steps"]) << file;
    EXPECT_EQ(loaded["max_range_m"], expected["max_range_m"]) << file;
  }
}

TEST(Assets, FoundBesideTheBinaryOrInTheSourceTree) {
  const fs::path report = FindAsset("report/report.html");
  EXPECT_TRUE(fs::exists(report));
  EXPECT_TRUE(fs::exists(FindAsset("workbench/layout.json")));
  try {
    FindAsset("no/such/asset.json");
    ADD_FAILURE() << "a missing asset must throw";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/asset.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CALIBENCH_ASSETS"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace calibench
