#include "core/evaluation/plane_sweep.h"

#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include "core/base/parallel.h"
#include "core/evaluation/crlb.h"

namespace calibench {
namespace {

struct Subset {
  std::vector<PairFeatures> features;
  CramerRaoBound bound;
};

// The usable pairs of one level's pool, with their indices in the simulation.
struct Pool {
  std::vector<PairFeatures> features;
  std::vector<int> sim_index;
  double mean_corner_sigma_px = 0.0;
};

// The same random subsets for every method, each with its own bound.
std::vector<Subset> DrawSubsets(const Pool& pool, const SimulationBoundInput& bound_input, int n,
                                int subsets, std::mt19937_64& rng) {
  std::vector<Subset> out;
  std::vector<int> order(pool.features.size());
  for (int s = 0; s < subsets; ++s) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    Subset subset;
    std::vector<int> sim_subset;
    for (int i = 0; i < n; ++i) {
      subset.features.push_back(pool.features[order[i]]);
      sim_subset.push_back(pool.sim_index[order[i]]);
    }
    subset.bound = SimulationBound(bound_input, sim_subset);
    out.push_back(std::move(subset));
  }
  return out;
}

// Mean and spread of the errors, and their RMS against the RMS bound.
void Aggregate(const std::vector<double>& t_err, const std::vector<double>& r_err, double bound_t2,
               double bound_r2, PlaneSweepCell* cell) {
  const double count = static_cast<double>(t_err.size());
  double rms_t = 0, rms_r = 0;
  for (size_t i = 0; i < t_err.size(); ++i) {
    cell->mean_mm += t_err[i] / count;
    cell->mean_deg += r_err[i] / count;
    rms_t += t_err[i] * t_err[i] / count;
    rms_r += r_err[i] * r_err[i] / count;
  }
  for (double v : t_err) cell->std_mm += (v - cell->mean_mm) * (v - cell->mean_mm) / count;
  cell->std_mm = std::sqrt(cell->std_mm);
  cell->ratio_t = std::sqrt(rms_t) / std::sqrt(bound_t2 / count);
  cell->ratio_r = std::sqrt(rms_r) / std::sqrt(bound_r2 / count);
}

PlaneSweepCell RunSubsets(const std::vector<Subset>& subsets, const Pose& truth,
                          const PipelineOptions& options) {
  std::vector<double> t_err, r_err;
  double bound_t2 = 0, bound_r2 = 0;
  PlaneSweepCell cell;
  // Solved in parallel, reduced in subset order: the cell does not depend on the thread count.
  std::vector<std::optional<SolverResult>> solutions(subsets.size());
  ParallelFor(subsets.size(), options.threads, [&](size_t s) {
    solutions[s] = SolveFromFeatures(subsets[s].features, options).solution;
  });
  for (size_t s = 0; s < subsets.size(); ++s) {
    const Subset& subset = subsets[s];
    const std::optional<SolverResult>& solution = solutions[s];
    if (!solution) {
      ++cell.failures;
      continue;
    }
    const PoseError e = ComputePoseError(solution->cam_from_lidar, truth);
    t_err.push_back(e.translation_m * 1000);
    r_err.push_back(e.rotation_rad * kRadToDeg);
    bound_t2 += std::pow(subset.bound.translation_rms_m * 1000, 2);
    bound_r2 += std::pow(subset.bound.rotation_rms_deg, 2);
    if (!solution->observability.well_constrained) ++cell.weak;
  }
  if (!t_err.empty()) Aggregate(t_err, r_err, bound_t2, bound_r2, &cell);
  return cell;
}

Pool ExtractPool(const Dataset& dataset, const PipelineOptions& options,
                 const std::function<void(const std::string&)>& log) {
  Pool pool;
  double corner_sigma_sum = 0.0;
  std::vector<PairFeatures> extracted(dataset.pairs.size());
  ParallelFor(dataset.pairs.size(), options.threads, [&](size_t p) {
    extracted[p] = ExtractPairFeatures(dataset, dataset.pairs[p], options);
  });
  for (size_t p = 0; p < dataset.pairs.size(); ++p) {
    PairFeatures& f = extracted[p];
    if (f.status == PairStatus::kAccepted || (f.lidar && f.camera)) {
      corner_sigma_sum += f.camera->corner_sigma_px;
      pool.features.push_back(f);
      pool.sim_index.push_back(static_cast<int>(p));
    } else if (log) {
      log("  pair " + dataset.pairs[p].id + " failed: " + f.reason);
    }
  }
  if (!pool.features.empty()) pool.mean_corner_sigma_px = corner_sigma_sum / pool.features.size();
  return pool;
}

// One noise level: simulate and extract the pool, then every (N, method) cell of column k.
void RunLevel(const PlaneSweepOptions& options, size_t k,
              const std::function<void(const std::string&)>& log, PlaneSweepResult* result) {
  SimOptions sim = options.sim;
  sim.lidar_range_noise_m = options.range_noise_m[k];
  sim.image_noise = options.image_noise[k];
  const std::filesystem::path dir = options.work_dir / ("noise_" + std::to_string(k));
  char line[256];
  std::snprintf(line, sizeof(line), "simulating %d pairs at LiDAR noise %.3f m into %s",
                sim.num_pairs, options.range_noise_m[k], dir.string().c_str());
  if (log) log(line);
  const Dataset dataset = SimulateDataset(sim, dir);
  const Pool pool = ExtractPool(dataset, options.pipeline, log);
  if (log) log("  " + std::to_string(pool.features.size()) + " usable pairs");
  if (pool.features.empty()) return;
  // The bound needs noise: at zero range noise the LiDAR plane would be exact.
  SimOptions bound_sim = sim;
  bound_sim.lidar_range_noise_m = std::max(options.range_noise_m[k], 1e-4);
  const SimulationBoundInput bound_input =
      MakeSimulationBoundInput(bound_sim, pool.mean_corner_sigma_px);
  std::mt19937_64 rng(1000 + k);
  for (size_t i = 0; i < options.sizes.size(); ++i) {
    const int n = options.sizes[i];
    if (n > static_cast<int>(pool.features.size())) {
      for (auto& per_method : result->cells) per_method[i][k].failures = options.subsets;
      continue;
    }
    const std::vector<Subset> drawn = DrawSubsets(pool, bound_input, n, options.subsets, rng);
    for (size_t m = 0; m < options.methods.size(); ++m) {
      PipelineOptions solve = options.pipeline;
      solve.solver.method = options.methods[m];
      result->cells[m][i][k] = RunSubsets(drawn, *dataset.cam_from_lidar_ground_truth, solve);
    }
  }
}

}  // namespace

bool PlaneSweepOptions::Check(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  if (range_noise_m.size() != image_noise.size())
    return fail("one image noise is needed per LiDAR noise level");
  for (size_t k = 0; k < range_noise_m.size(); ++k)
    if (range_noise_m[k] < 0 || image_noise[k] < 0) return fail("noise levels must be >= 0");
  for (int n : sizes)
    if (n < 1) return fail("numbers of pairs must be >= 1");
  if (subsets < 1) return fail("subsets must be >= 1");
  if (methods.empty()) return fail("at least one method is needed");
  return pipeline.Check(why) && sim.Check(why);
}

PlaneSweepResult RunPlaneSweep(const PlaneSweepOptions& options,
                               const std::function<void(const std::string&)>& log) {
  std::string why;
  CALIBENCH_CHECK(options.Check(&why));
  PlaneSweepResult result;
  result.options = options;
  result.cells.assign(
      options.methods.size(),
      std::vector<std::vector<PlaneSweepCell>>(
          options.sizes.size(), std::vector<PlaneSweepCell>(options.range_noise_m.size())));
  for (size_t k = 0; k < options.range_noise_m.size(); ++k) RunLevel(options, k, log, &result);
  return result;
}

std::string FormatPlaneSweepTable(const PlaneSweepResult& result) {
  const PlaneSweepOptions& options = result.options;
  std::ostringstream out;
  for (size_t m = 0; m < options.methods.size(); ++m) {
    out << "\n**" << SolverMethodName(options.methods[m])
        << "**: mean / std translation error [mm], mean rotation error [deg], error / "
           "Cramér–Rao bound (translation, rotation), subsets not well constrained, failed\n\n";
    out << "| N |";
    for (double s : options.range_noise_m) out << " σ_l = " << s * 1000 << " mm |";
    out << "\n|---|";
    for (size_t k = 0; k < options.range_noise_m.size(); ++k) out << "---|";
    out << "\n";
    for (size_t i = 0; i < options.sizes.size(); ++i) {
      out << "| " << options.sizes[i] << " |";
      for (const PlaneSweepCell& c : result.cells[m][i]) {
        char cell[160];
        std::snprintf(cell, sizeof(cell), " %.2f / %.2f, %.3f° (×%.2f, ×%.2f; %d, %d) |", c.mean_mm,
                      c.std_mm, c.mean_deg, c.ratio_t, c.ratio_r, c.weak, c.failures);
        out << cell;
      }
      out << "\n";
    }
  }
  return out.str();
}

}  // namespace calibench
