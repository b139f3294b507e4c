#include "tests/test_support.h"

#include <array>
#include <cstdio>
#include <cstdlib>

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

}  // namespace calibench::test
