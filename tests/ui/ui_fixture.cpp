#include "tests/ui/ui_fixture.h"

#include <unistd.h>

#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench::test {

std::filesystem::path UiDataset() {
  static const std::filesystem::path manifest = [] {
    SimOptions sim = SimPreset("demo");
    sim.num_pairs = 4;
    sim.seed = 3;
    // One folder per process: ctest runs tests in parallel processes.
    const auto dir = TempDir("ui_dataset_" + std::to_string(getpid()));
    return SimulateDataset(sim, dir).manifest;
  }();
  return manifest;
}

}  // namespace calibench::test
