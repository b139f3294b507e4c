#include "tests/test_support.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/geometry/geometry.h"
#include "core/results/result_json.h"
#include "tests/acfr_manifest.h"

namespace calibench::test {

std::optional<std::filesystem::path> SharedDir() {
  const char* env = std::getenv("CALIBENCH_SHARED_DIR");
  const std::filesystem::path dir = env ? env : CALIBENCH_SHARED_DIR_DEFAULT;
  if (std::filesystem::is_directory(dir / "datasets")) return std::filesystem::canonical(dir);
  return std::nullopt;
}

namespace {

// Claims test_tmp/<name> for the running test (TempDir's rule); outside a test, nothing to check.
void ClaimTempDir(const std::filesystem::path& root, const std::string& name) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  if (!test) return;
  const std::string me = std::string(test->test_suite_name()) + "." + test->name();
  std::string key = name;
  std::replace(key.begin(), key.end(), '/', '%');
  const std::filesystem::path owners = root / ".owners";
  std::filesystem::create_directories(owners);
  const std::filesystem::path marker = owners / key;
  // O_EXCL: of two tests starting at once exactly one creates the marker.
  if (const int fd = ::open(marker.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644); fd >= 0) {
    const bool written = ::write(fd, me.data(), me.size()) == static_cast<ssize_t>(me.size());
    ::close(fd);
    EXPECT_TRUE(written) << "cannot write " << marker;
    return;
  }
  std::string owner;
  for (int attempt = 0; attempt < 50 && owner.empty(); ++attempt) {  // its owner is writing it
    owner = ReadFileBytes(marker);
    if (owner.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(owner, me) << "test_tmp/" << name << " belongs to test " << owner
                       << ": give each test a folder of its own (or, if that test no longer "
                          "exists, delete "
                       << marker << ")";
}

}  // namespace

std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path root = std::filesystem::path(CALIBENCH_BINARY_DIR) / "test_tmp";
  ClaimTempDir(root, name);
  const std::filesystem::path dir = root / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string CalibenchExe() {
  const char* env = std::getenv("CALIBENCH_EXE");
  return env ? env : (std::string(CALIBENCH_BINARY_DIR) + "/calibench");
}

std::string ReadFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<std::filesystem::path> TemporariesBeside(const std::filesystem::path& path) {
  std::vector<std::filesystem::path> found;
  const std::string prefix = path.filename().string() + ".tmp";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(path.parent_path(), ec))
    if (entry.path().filename().string().rfind(prefix, 0) == 0) found.push_back(entry.path());
  return found;
}

int RunCommand(const std::string& command, std::string* output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) text.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (output) *output = text;
  return WEXITSTATUS(status);
}

void ExpectNearAcfrReference(const Pose& cam_from_lidar, const char* what) {
  const Pose reference = AcfrReferenceCamFromLidar();
  const Vec3 difference =
      cam_from_lidar.inverse().translation() - reference.inverse().translation();
  const double angle = RotationAngle(cam_from_lidar.linear(), reference.linear());
  std::printf(
      "%s: %.1f mm, %.3f deg from the authors' reference (LiDAR frame x/y/z %+.1f / %+.1f / "
      "%+.1f mm)\n",
      what, difference.norm() * 1e3, angle * 180 / M_PI, difference.x() * 1e3, difference.y() * 1e3,
      difference.z() * 1e3);
  EXPECT_LT(std::abs(difference.x()), 2 * 0.004);
  EXPECT_LT(std::abs(difference.y()), 2 * 0.018);
  EXPECT_LT(std::abs(difference.z()), 2 * 0.030);
  EXPECT_LT(angle, 2 * 0.66 * M_PI / 180);
}

SimOptions A3Hdl64Options(int pairs, double range_noise_m, std::uint64_t seed) {
  SimOptions options = SimPreset("paper");
  options.board = BoardPreset("a3");
  options.lidar = LidarModel::kHdl64;
  options.min_distance_m = 1.5;
  options.max_distance_m = 6.0;
  options.num_pairs = pairs;
  options.lidar_range_noise_m = range_noise_m;
  options.seed = seed;
  return options;
}

void WriteBareResult(const std::filesystem::path& path, const Pose& cam_from_lidar) {
  nlohmann::json root =
      ResultHeaderJson(ResultNames{}, cam_from_lidar, Mat6::Zero(), ObservabilityReport{});
  root["pairs"] = nlohmann::json::array();
  WriteResultJson(path, root);
}

}  // namespace calibench::test
