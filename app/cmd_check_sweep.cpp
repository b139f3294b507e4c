// `calibench check-sweep`: the targetless check measured on simulated textured rooms
// (core/evaluation/check_sweep.h): catch rates per error size, false alarms on the truth, χ².
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "core/evaluation/check_sweep.h"

namespace calibench::app {

int RunCheckSweep(int argc, char** argv) {
  CLI::App app{
      "Measure the targetless check on simulated textured rooms: per seed a room (boxes, pillars, "
      "posters), a rig and a LiDAR give frames; the check judges the true extrinsic (a false "
      "alarm if miscalibrated) and the truth moved by each error size in a random direction "
      "(caught if miscalibrated); the estimate's error against its sigma as chi2.",
      "calibench check-sweep"};
  CheckSweepOptions options;
  bool json = false;
  std::string write_scene;
  app.add_option("--lidar", options.lidar, "vlp16 | os0-128 | hdl64 | mid40 | avia | mid360")
      ->capture_default_str();
  app.add_flag("--moving", options.moving,
               "the rig drives through the room (else it stands still)");
  app.add_option("--seeds", options.seeds, "rooms")->capture_default_str();
  app.add_option("--first-seed", options.first_seed, "the first room's seed")
      ->capture_default_str();
  app.add_option("--frames", options.frames, "frames per room")->capture_default_str();
  app.add_option("--range-noise", options.range_noise_m, "LiDAR range noise sigma [m]")
      ->capture_default_str();
  app.add_option("--image-noise", options.image_noise, "image noise sigma [0,1]")
      ->capture_default_str();
  app.add_option("--hold", options.livox_hold_s,
                 "Livox-class: seconds of returns integrated per frame (a still hold)")
      ->capture_default_str();
  app.add_option("--rotation-errors", options.rotation_errors_deg, "error sizes [deg]")
      ->capture_default_str();
  app.add_option("--translation-errors", options.translation_errors_m, "error sizes [m]")
      ->capture_default_str();
  app.add_option("--tolerance-deg", options.check.tolerance_deg,
                 "the check's tolerance in rotation [deg]")
      ->capture_default_str();
  app.add_option("--tolerance-m", options.check.tolerance_m,
                 "the check's tolerance in translation [m]")
      ->capture_default_str();
  app.add_option("--threads", options.threads, "worker threads (0 = all cores)")
      ->capture_default_str();
  app.add_option("--write-scene", write_scene,
                 "write the first room's frames as a dataset folder (and truth.result.json) "
                 "instead of sweeping");
  app.add_flag("--json", json, "print exactly one JSON object on stdout");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  options.check.alignment.threads = options.threads;
  std::string why;
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench check-sweep: %s\n", why.c_str());
    return kUsage;
  }
  if (!write_scene.empty()) {
    WriteCheckScene(SimulateCheckScene(options, options.first_seed), write_scene);
    std::printf(
        "wrote %d frames of room %llu (%s, %s rig) into %s, the truth in "
        "truth.result.json\n",
        options.frames, static_cast<unsigned long long>(options.first_seed), options.lidar.c_str(),
        options.moving ? "moving" : "still", write_scene.c_str());
    return kOk;
  }
  MachineStdout out(json);
  const CheckSweepResult result = RunCheckSweep(options, [](int done, int seeds) {
    std::fprintf(stderr, "[%d/%d] rooms checked\n", done, seeds);
  });
  if (json)
    out.Print(CheckSweepJson(result));
  else
    std::printf("%s", FormatCheckSweep(result).c_str());
  return kOk;
}

}  // namespace calibench::app
