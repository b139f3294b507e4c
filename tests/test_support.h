// Helpers shared by the test suites: tolerance matchers for Eigen types, the shared/ folder,
// temporary directories.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/sim/sim.h"

namespace calibench::test {

// ../shared when present. When it is missing: GTEST_SKIP with a clear message, unless the
// environment sets CALIBENCH_REQUIRE_SHARED=1 (as .ci/run does), in which case the test fails.
std::optional<std::filesystem::path> SharedDir();

// A fresh, empty directory under the build tree for one test. The folder is that test's alone:
// ctest runs tests at once, and two that named one folder would empty it under each other. So the
// first test to ask for a name owns it (build/test_tmp/.owners/<name>), and any other test asking
// for it fails at once, naming both, however the two happen to be timed.
std::filesystem::path TempDir(const std::string& name);

// The calibench executable built next to the tests (from $CALIBENCH_EXE).
std::string CalibenchExe();

// The whole file as bytes (empty when it cannot be read).
std::string ReadFileBytes(const std::filesystem::path& path);

// Temporary files (WriteFileAtomically's "<name>.tmp.*") left beside `path`.
std::vector<std::filesystem::path> TemporariesBeside(const std::filesystem::path& path);

// Runs a shell command, returns its exit code; stdout+stderr go to *output when given.
int RunCommand(const std::string& command, std::string* output = nullptr);

template <typename A, typename B>
::testing::AssertionResult MatrixNear(const A& actual, const B& expected, double tolerance) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols())
    return ::testing::AssertionFailure() << "size mismatch";
  const double err = (actual - expected).cwiseAbs().maxCoeff();
  if (err <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "max abs difference " << err << " > " << tolerance << "\nactual:\n"
         << actual << "\nexpected:\n"
         << expected;
}

// Checks (gtest EXPECTs) that an estimate lies within twice the reference's own spread: the
// authors give it for lidar_from_cam (the camera's position in the LiDAR frame) as 4 / 18 / 30 mm
// in x / y / z and 0.40–0.66 deg per angle. Prints the differences, prefixed by `what`.
void ExpectNearAcfrReference(const Pose& cam_from_lidar, const char* what);

// A result file holding only cam_from_lidar (zero covariance, no pairs): a calibration to check.
void WriteBareResult(const std::filesystem::path& path, const Pose& cam_from_lidar);

// The issue-5 protocol's simulation: an A3 checkerboard, an HDL-64, boards at 1.5–6 m.
SimOptions A3Hdl64Options(int pairs, double range_noise_m, std::uint64_t seed);

}  // namespace calibench::test

// Skips (or fails under CALIBENCH_REQUIRE_SHARED=1) when ../shared is absent; binds `shared`.
#define CALIBENCH_REQUIRE_SHARED_DIR(shared)                                                \
  const auto shared##_opt = ::calibench::test::SharedDir();                                 \
  if (!shared##_opt) {                                                                      \
    if (std::getenv("CALIBENCH_REQUIRE_SHARED") &&                                          \
        std::string(std::getenv("CALIBENCH_REQUIRE_SHARED")) == "1") {                      \
      FAIL() << "../shared is required (CALIBENCH_REQUIRE_SHARED=1) but was not found";     \
    }                                                                                       \
    GTEST_SKIP() << "../shared/datasets not found next to the repository: skipping a test " \
                    "on real data (set CALIBENCH_SHARED_DIR to point at it)";               \
  }                                                                                         \
  const std::filesystem::path shared = *shared##_opt
