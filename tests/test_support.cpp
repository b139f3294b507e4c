#include "tests/test_support.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

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

std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(CALIBENCH_BINARY_DIR) / "test_tmp" / name;
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
