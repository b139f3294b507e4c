#include "tests/ui/golden.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/io/image_io.h"
#include "tests/test_support.h"

namespace calibench::ui {
namespace {

// Per-channel tolerance and the share of pixels allowed beyond it: llvmpipe is deterministic,
// the slack covers font hinting and rasteriser differences between Mesa builds.
constexpr int kChannelTolerance = 24;
constexpr double kMaxDifferingFraction = 0.003;

}  // namespace

std::unique_ptr<gfx::GlContext> HeadlessOrSkip() {
  std::string why;
  auto context = gfx::CreateHeadlessContext(gfx::HeadlessBackend::kAuto, &why);
  if (!context && std::getenv("CALIBENCH_REQUIRE_GL")) ADD_FAILURE() << "no headless GL: " << why;
  return context;
}

void ExpectMatchesGolden(const ImageU8& actual, const std::string& name) {
  const std::filesystem::path golden =
      std::filesystem::path(CALIBENCH_GOLDEN_DIR) / (name + ".png");
  if (const char* update = std::getenv("CALIBENCH_UPDATE_GOLDENS");
      update && std::string(update) == "1") {
    SaveImage(golden, actual);
    std::printf("updated golden %s\n", golden.c_str());
    return;
  }
  ASSERT_TRUE(std::filesystem::exists(golden))
      << golden << " is missing: run once with CALIBENCH_UPDATE_GOLDENS=1 and look at it";
  const ImageU8 expected = LoadImage(golden);
  ASSERT_EQ(expected.width, actual.width) << name;
  ASSERT_EQ(expected.height, actual.height) << name;
  ImageU8 diff = actual;
  size_t differing = 0;
  for (size_t p = 0; p < actual.data.size() / 3; ++p) {
    int worst = 0;
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(actual.data[3 * p + c] - expected.data[3 * p + c]));
    const bool bad = worst > kChannelTolerance;
    differing += bad;
    for (int c = 0; c < 3; ++c)
      diff.data[3 * p + c] = bad ? (c == 2 ? 255 : 0) : actual.data[3 * p + c] / 4;
  }
  const double fraction = static_cast<double>(differing) / (actual.width * actual.height);
  if (fraction > kMaxDifferingFraction) {
    const auto dir = test::TempDir("golden_failure_" + name);
    SaveImage(dir / "actual.png", actual);
    SaveImage(dir / "diff.png", diff);
    ADD_FAILURE() << name << ": " << differing << " pixels (" << fraction * 100
                  << " %) differ by more than " << kChannelTolerance << "; see "
                  << dir / "actual.png"
                  << " and " << dir / "diff.png";
  }
}

}  // namespace calibench::ui
