// The paper's Table 1 protocol (Ca²Lib Section 4.1) on simulated data: for each noise level,
// simulate a pool of pairs once, extract features once, then solve many random subsets of N.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/pipeline.h"
#include "core/sim.h"

namespace calibench::app {
namespace {

std::vector<double> ParseList(const std::string& text) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) values.push_back(std::stod(item));
  return values;
}

struct Cell {
  double mean_mm = 0, std_mm = 0, mean_deg = 0;
  double mean_constrained_mm = 0;  // over the subsets the solver reported well constrained
  int weak = 0;                    // subsets reported not well constrained
  int failures = 0;                // subsets without a result
};

Cell RunSubsets(const std::vector<PairFeatures>& pool, int n, int subsets, const Pose& truth,
                const PipelineOptions& options, std::mt19937_64& rng) {
  std::vector<double> t_err, r_err, t_err_constrained;
  Cell cell;
  for (int s = 0; s < subsets; ++s) {
    std::vector<PairFeatures> subset = pool;
    std::shuffle(subset.begin(), subset.end(), rng);
    subset.resize(n);
    const CalibrationOutcome outcome = SolveFromFeatures(subset, options);
    if (!outcome.solution) {
      ++cell.failures;
      continue;
    }
    const PoseError e = ComputePoseError(outcome.solution->cam_from_lidar, truth);
    t_err.push_back(e.translation_m * 1000);
    r_err.push_back(e.rotation_rad * 180 / M_PI);
    if (outcome.solution->observability.well_constrained) {
      t_err_constrained.push_back(t_err.back());
    } else {
      ++cell.weak;
    }
  }
  if (t_err.empty()) return cell;
  for (double v : t_err) cell.mean_mm += v / t_err.size();
  for (double v : r_err) cell.mean_deg += v / r_err.size();
  for (double v : t_err_constrained) cell.mean_constrained_mm += v / t_err_constrained.size();
  for (double v : t_err) cell.std_mm += (v - cell.mean_mm) * (v - cell.mean_mm) / t_err.size();
  cell.std_mm = std::sqrt(cell.std_mm);
  return cell;
}

}  // namespace

int RunSweep(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--kind" || std::string(argv[i]).rfind("--kind=", 0) == 0)
      return RunSweepLrf(argc, argv);
  CLI::App app{"Error vs. number of pairs and LiDAR noise (Ca²Lib Table 1 protocol).",
               "calibench sweep"};
  std::string work_dir = "out/sweep", sizes_text = "3,4,5,10,20,30,39",
              noise_text = "0,0.008,0.016", image_noise_text = "0,0.007,0.014", table_path;
  int subsets = 40;
  app.add_option("--work-dir", work_dir, "where the simulated pools are written")
      ->capture_default_str();
  app.add_option("--sizes", sizes_text, "numbers of pairs N")->capture_default_str();
  app.add_option("--subsets", subsets, "random subsets per N")->capture_default_str();
  app.add_option("--noise-levels", noise_text, "LiDAR range noise levels [m]")
      ->capture_default_str();
  app.add_option("--image-noise-levels", image_noise_text, "image noise per level, [0,1] units")
      ->capture_default_str();
  app.add_option("--table", table_path, "also write the markdown table here");
  SimFlags sim_flags;
  sim_flags.preset = "paper";
  AddSimFlags(app, sim_flags);
  PipelineFlags flags;
  AddPipelineFlags(app, flags, /*with_selection=*/false);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  std::string why;
  std::vector<double> sizes, noises, image_noises;
  try {
    sizes = ParseList(sizes_text);
    noises = ParseList(noise_text);
    image_noises = ParseList(image_noise_text);
  } catch (const std::exception&) {
    std::fprintf(stderr,
                 "calibench sweep: --sizes/--noise-levels/--image-noise-levels take "
                 "comma-separated numbers\n");
    return kUsage;
  }
  if (image_noises.size() != noises.size() || subsets < 1 || !FinalizePipelineFlags(flags, &why)) {
    std::fprintf(
        stderr, "calibench sweep: %s\n",
        why.empty()
            ? "--image-noise-levels needs one value per --noise-levels entry, --subsets >= 1"
            : why.c_str());
    return kUsage;
  }
  std::vector<std::vector<Cell>> table(sizes.size(), std::vector<Cell>(noises.size()));
  for (size_t k = 0; k < noises.size(); ++k) {
    SimFlags level = sim_flags;
    level.lidar_noise = noises[k];
    level.image_noise = image_noises[k];
    SimOptions sim;
    if (!BuildSimOptions(level, &sim, &why)) {
      std::fprintf(stderr, "calibench sweep: %s\n", why.c_str());
      return kUsage;
    }
    const std::string dir = work_dir + "/noise_" + std::to_string(k);
    std::fprintf(stderr, "simulating %d pairs at LiDAR noise %.3f m into %s\n", sim.num_pairs,
                 noises[k], dir.c_str());
    const Dataset dataset = SimulateDataset(sim, dir);
    std::vector<PairFeatures> pool;
    PipelineOptions extract = flags.options;
    for (const PairEntry& pair : dataset.pairs) {
      PairFeatures f = ExtractPairFeatures(dataset, pair, extract);
      if (f.status == PairStatus::kAccepted)
        pool.push_back(f);
      else
        std::fprintf(stderr, "  pair %s failed: %s\n", pair.id.c_str(), f.reason.c_str());
    }
    std::fprintf(stderr, "  %zu usable pairs\n", pool.size());
    std::mt19937_64 rng(1000 + k);
    for (size_t i = 0; i < sizes.size(); ++i) {
      const int n = static_cast<int>(sizes[i]);
      if (n > static_cast<int>(pool.size())) {
        table[i][k].failures = subsets;
        continue;
      }
      table[i][k] =
          RunSubsets(pool, n, subsets, *dataset.cam_from_lidar_ground_truth, flags.options, rng);
    }
  }
  std::ostringstream out;
  out << "| N |";
  for (double s : noises)
    out << " σ_l = " << s * 1000
        << " mm: mean / std [mm], rot [deg] (well-constrained only [mm], weak, failed) |";
  out << "\n|---|";
  for (size_t k = 0; k < noises.size(); ++k) out << "---|";
  out << "\n";
  for (size_t i = 0; i < sizes.size(); ++i) {
    out << "| " << sizes[i] << " |";
    for (const Cell& c : table[i]) {
      char cell[128];
      std::snprintf(cell, sizeof(cell), " %.2f / %.2f, %.3f (%.2f, %d, %d) |", c.mean_mm, c.std_mm,
                    c.mean_deg, c.mean_constrained_mm, c.weak, c.failures);
      out << cell;
    }
    out << "\n";
  }
  std::printf("%s", out.str().c_str());
  if (!table_path.empty()) std::ofstream(table_path) << out.str();
  return kOk;
}

}  // namespace calibench::app
