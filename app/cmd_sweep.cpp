// The paper's Table 1 protocol (Ca²Lib Section 4.1) on simulated data: for each noise level,
// simulate a pool of pairs once, extract features once, then solve many random subsets of N.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "app/pipeline_flags.h"
#include "app/sim_flags.h"
#include "core/lidar_camera/pipeline.h"
#include "core/sim/crlb.h"
#include "core/sim/sim.h"

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
  double ratio_t = 0, ratio_r = 0;  // RMS error / RMS bound over the subsets
  int weak = 0;                     // subsets reported not well constrained
  int failures = 0;                 // subsets without a result
};

struct Subset {
  std::vector<PairFeatures> features;
  CramerRaoBound bound;
};

// The same random subsets for every method, each with its own bound.
std::vector<Subset> DrawSubsets(const std::vector<PairFeatures>& pool,
                                const std::vector<int>& sim_index,
                                const SimulationBoundInput& bound_input, int n, int subsets,
                                std::mt19937_64& rng) {
  std::vector<Subset> out;
  std::vector<int> order(pool.size());
  for (int s = 0; s < subsets; ++s) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    Subset subset;
    std::vector<int> sim_subset;
    for (int i = 0; i < n; ++i) {
      subset.features.push_back(pool[order[i]]);
      sim_subset.push_back(sim_index[order[i]]);
    }
    subset.bound = SimulationBound(bound_input, sim_subset);
    out.push_back(std::move(subset));
  }
  return out;
}

Cell RunSubsets(const std::vector<Subset>& subsets, const Pose& truth,
                const PipelineOptions& options) {
  std::vector<double> t_err, r_err;
  double bound_t2 = 0, bound_r2 = 0;
  Cell cell;
  for (const Subset& subset : subsets) {
    const CalibrationOutcome outcome = SolveFromFeatures(subset.features, options);
    if (!outcome.solution) {
      ++cell.failures;
      continue;
    }
    const PoseError e = ComputePoseError(outcome.solution->cam_from_lidar, truth);
    t_err.push_back(e.translation_m * 1000);
    r_err.push_back(e.rotation_rad * 180 / M_PI);
    bound_t2 += std::pow(subset.bound.translation_rms_m * 1000, 2);
    bound_r2 += std::pow(subset.bound.rotation_rms_deg, 2);
    if (!outcome.solution->observability.well_constrained) ++cell.weak;
  }
  if (t_err.empty()) return cell;
  const double count = static_cast<double>(t_err.size());
  double rms_t = 0, rms_r = 0;
  for (size_t i = 0; i < t_err.size(); ++i) {
    cell.mean_mm += t_err[i] / count;
    cell.mean_deg += r_err[i] / count;
    rms_t += t_err[i] * t_err[i] / count;
    rms_r += r_err[i] * r_err[i] / count;
  }
  for (double v : t_err) cell.std_mm += (v - cell.mean_mm) * (v - cell.mean_mm) / count;
  cell.std_mm = std::sqrt(cell.std_mm);
  cell.ratio_t = std::sqrt(rms_t) / std::sqrt(bound_t2 / count);
  cell.ratio_r = std::sqrt(rms_r) / std::sqrt(bound_r2 / count);
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
  std::string methods_text = "weighted-ml,ca2lib-gn,kim";
  app.add_option("--work-dir", work_dir, "where the simulated pools are written")
      ->capture_default_str();
  app.add_option("--sizes", sizes_text, "numbers of pairs N")->capture_default_str();
  app.add_option("--subsets", subsets, "random subsets per N")->capture_default_str();
  app.add_option("--noise-levels", noise_text, "LiDAR range noise levels [m]")
      ->capture_default_str();
  app.add_option("--image-noise-levels", image_noise_text, "image noise per level, [0,1] units")
      ->capture_default_str();
  app.add_option("--table", table_path, "also write the markdown table here");
  app.add_option("--methods", methods_text, "solvers to compare (weighted-ml, ca2lib-gn, kim)")
      ->capture_default_str();
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
  std::vector<SolverMethod> methods;
  {
    std::stringstream ss(methods_text);
    std::string name;
    while (std::getline(ss, name, ',')) {
      const auto method = ParseSolverMethod(name);
      if (!method) {
        std::fprintf(stderr, "calibench sweep: unknown method '%s' in --methods\n", name.c_str());
        return kUsage;
      }
      methods.push_back(*method);
    }
  }
  // table[method][size][noise]
  std::vector<std::vector<std::vector<Cell>>> table(
      methods.size(),
      std::vector<std::vector<Cell>>(sizes.size(), std::vector<Cell>(noises.size())));
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
    std::vector<int> sim_index;
    PipelineOptions extract = flags.options;
    double corner_sigma_sum = 0.0;
    for (size_t p = 0; p < dataset.pairs.size(); ++p) {
      PairFeatures f = ExtractPairFeatures(dataset, dataset.pairs[p], extract);
      if (f.status == PairStatus::kAccepted || (f.lidar && f.camera)) {
        corner_sigma_sum += f.camera->corner_sigma_px;
        pool.push_back(f);
        sim_index.push_back(static_cast<int>(p));
      } else {
        std::fprintf(stderr, "  pair %s failed: %s\n", dataset.pairs[p].id.c_str(),
                     f.reason.c_str());
      }
    }
    std::fprintf(stderr, "  %zu usable pairs\n", pool.size());
    if (pool.empty()) continue;
    // The bound needs noise: at zero range noise the LiDAR plane would be exact.
    const double corner_sigma = corner_sigma_sum / pool.size();
    SimOptions bound_sim = sim;
    bound_sim.lidar_range_noise_m = std::max(noises[k], 1e-4);
    const SimulationBoundInput bound_input = MakeSimulationBoundInput(bound_sim, corner_sigma);
    std::mt19937_64 rng(1000 + k);
    for (size_t i = 0; i < sizes.size(); ++i) {
      const int n = static_cast<int>(sizes[i]);
      if (n > static_cast<int>(pool.size())) {
        for (auto& per_method : table) per_method[i][k].failures = subsets;
        continue;
      }
      const std::vector<Subset> drawn = DrawSubsets(pool, sim_index, bound_input, n, subsets, rng);
      for (size_t m = 0; m < methods.size(); ++m) {
        PipelineOptions options = flags.options;
        options.solver.method = methods[m];
        table[m][i][k] = RunSubsets(drawn, *dataset.cam_from_lidar_ground_truth, options);
      }
    }
  }
  std::ostringstream out;
  for (size_t m = 0; m < methods.size(); ++m) {
    out << "\n**" << SolverMethodName(methods[m])
        << "**: mean / std translation error [mm], mean rotation error [deg], error / "
           "Cramér–Rao bound (translation, rotation), subsets not well constrained, failed\n\n";
    out << "| N |";
    for (double s : noises) out << " σ_l = " << s * 1000 << " mm |";
    out << "\n|---|";
    for (size_t k = 0; k < noises.size(); ++k) out << "---|";
    out << "\n";
    for (size_t i = 0; i < sizes.size(); ++i) {
      out << "| " << sizes[i] << " |";
      for (const Cell& c : table[m][i]) {
        char cell[160];
        std::snprintf(cell, sizeof(cell), " %.2f / %.2f, %.3f° (×%.2f, ×%.2f; %d, %d) |", c.mean_mm,
                      c.std_mm, c.mean_deg, c.ratio_t, c.ratio_r, c.weak, c.failures);
        out << cell;
      }
      out << "\n";
    }
  }
  std::printf("%s", out.str().c_str());
  if (!table_path.empty()) std::ofstream(table_path) << out.str();
  return kOk;
}

}  // namespace calibench::app
