// `calibench sweep --guided`: guided against random board placement on simulated data
// (core/evaluation/guided_sweep.h).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/evaluation/guided_sweep.h"

namespace calibench::app {

int RunSweepGuided(int argc, char** argv) {
  CLI::App app{
      "Guided capture against random placement on simulated data: each board is held where "
      "`advise` says (perturbed as a hand holds it) or placed at random, pair by pair through "
      "the pipeline, until the stop rule says done.",
      "calibench sweep --guided"};
  GuidedSweepOptions options;
  bool guided = false;
  std::string table_path;
  double hand_cm = 10.0;
  app.add_flag("--guided", guided, "this protocol");
  app.add_option("--goal-mm", options.goal.translation_mm, "goal: 1σ per axis [mm]")
      ->capture_default_str();
  app.add_option("--goal-deg", options.goal.rotation_deg, "goal: 1σ per axis [deg]")
      ->capture_default_str();
  app.add_option("--seeds", options.seeds, "simulated captures per placement")
      ->capture_default_str();
  app.add_option("--first-seed", options.first_seed, "the first simulation seed")
      ->capture_default_str();
  app.add_option("--max-pairs", options.max_pairs, "poses held at most per capture")
      ->capture_default_str();
  app.add_option("--hand-cm", hand_cm, "the hand's position error, ± per axis [cm]")
      ->capture_default_str();
  app.add_option("--hand-deg", options.hand_rotation_deg, "the hand's turn, at most [deg]")
      ->capture_default_str();
  bool no_hand_model = false;
  app.add_flag("--no-hand-model", no_hand_model,
               "guidance scores poses as if they were held exactly (as before it knew the hand)");
  app.add_option("--table", table_path, "also write the markdown table here");
  SimFlags sim_flags;
  AddSimFlags(app, sim_flags);
  PipelineFlags flags;
  AddPipelineFlags(app, flags, /*with_selection=*/false);
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  std::string why;
  if (!BuildSimOptions(sim_flags, &options.sim, &why) || !FinalizePipelineFlags(flags, &why)) {
    std::fprintf(stderr, "calibench sweep --guided: %s\n", why.c_str());
    return kUsage;
  }
  options.pipeline = flags.options;
  options.threads = flags.options.threads;
  options.hand_translation_m = hand_cm / 100.0;
  // Guidance expects the hand the protocol simulates (advise --hand-tolerance-m/-deg).
  options.guidance.hand_tolerance_m = no_hand_model ? 0.0 : options.hand_translation_m;
  options.guidance.hand_tolerance_deg = no_hand_model ? 0.0 : options.hand_rotation_deg;
  if (no_hand_model) options.guidance.hand_samples = 1;
  if (!options.Check(&why)) {
    std::fprintf(stderr, "calibench sweep --guided: %s\n", why.c_str());
    return kUsage;
  }
  const GuidedSweepResult result = RunGuidedSweep(
      options, [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  const std::string table = FormatGuidedSweepTable(result);
  return PrintAndWriteTable(table, table_path, "calibench sweep --guided");
}

}  // namespace calibench::app
