#include "core/evaluation/lrf_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "core/base/parallel.h"

namespace calibench {

namespace {

using SweepError = std::pair<double, double>;  // (rotation deg, translation mm)

// One seed's outcome: per (method, size) its error, or nothing when the solve failed.
struct SeedRun {
  std::vector<std::vector<std::optional<SweepError>>> errors;
  int observations_total = 0, observations_failed = 0;
};

// Seed number `s`: its own simulation, features, and a solve per (method, size).
SeedRun RunSeed(const LrfSweepOptions& options, int max_size, size_t s) {
  SeedRun run;
  run.errors.assign(options.methods.size(),
                    std::vector<std::optional<SweepError>>(options.sizes.size()));
  LrfSimOptions sim = options.sim;
  // A few extra poses, so that an observation whose features fail (reported below) does not
  // leave the seed short of max_size usable ones.
  sim.observations = max_size + max_size / 2 + 2;
  sim.seed = options.first_seed + static_cast<std::uint64_t>(s);
  const std::vector<Pose> poses = SampleTargetPoses(sim);
  std::vector<LrfObservation> usable;
  for (size_t k = 0; k < poses.size() && static_cast<int>(usable.size()) < max_size; ++k) {
    const LrfSimObservation rendered =
        RenderLrfObservation(sim, poses[k], sim.seed * 1000003ull + k);
    LrfObservation observation;
    observation.id = std::to_string(k);
    observation.scan = ExtractScanFeatures(rendered.scan, sim.target, options.pipeline.scan);
    observation.depth = ExtractDepthFeatures(rendered.depth, sim.target, options.pipeline.depth);
    ++run.observations_total;
    if (observation.scan.ok && observation.depth.ok)
      usable.push_back(std::move(observation));
    else
      ++run.observations_failed;
  }
  for (size_t m = 0; m < options.methods.size(); ++m) {
    LrfSolverOptions solver = options.pipeline.solver;
    solver.method = options.methods[m];
    for (size_t i = 0; i < options.sizes.size(); ++i) {
      const int n = options.sizes[i];
      if (static_cast<int>(usable.size()) < n) continue;
      const std::vector<LrfObservation> first(usable.begin(), usable.begin() + n);
      const LrfSolution solution = SolveLrf(first, solver);
      if (!solution.ok) continue;
      const PoseError e = ComputePoseError(solution.cam_from_lrf, sim.cam_from_lrf);
      run.errors[m][i] = std::make_pair(e.rotation_rad * kRadToDeg, e.translation_m * 1e3);
    }
  }
  return run;
}

}  // namespace

LrfSweepResult RunLrfSweep(const LrfSweepOptions& options,
                           const std::function<void(int, int)>& progress) {
  LrfSweepResult result;
  result.sizes = options.sizes;
  result.methods = options.methods;
  const int max_size = *std::max_element(options.sizes.begin(), options.sizes.end());
  // errors[method][size] = (rotation deg, translation mm) per successful seed
  std::vector<std::vector<std::vector<std::pair<double, double>>>> errors(
      options.methods.size(),
      std::vector<std::vector<std::pair<double, double>>>(options.sizes.size()));
  std::vector<std::vector<int>> failures(options.methods.size(),
                                         std::vector<int>(options.sizes.size(), 0));
  std::vector<SeedRun> runs(static_cast<size_t>(options.seeds));
  // Seeds run in parallel (options.pipeline.threads); each has its own simulation, and they are
  // reduced in seed order, so the table does not depend on the thread count.
  auto run_seed = [&](size_t s) { runs[s] = RunSeed(options, max_size, s); };
  ParallelFor(runs.size(), options.pipeline.threads, run_seed, [&](int finished, size_t) {
    if (progress) progress(finished, options.seeds);
  });
  for (const SeedRun& run : runs) {
    result.observations_total += run.observations_total;
    result.observations_failed += run.observations_failed;
    for (size_t m = 0; m < options.methods.size(); ++m)
      for (size_t i = 0; i < options.sizes.size(); ++i) {
        if (run.errors[m][i])
          errors[m][i].push_back(*run.errors[m][i]);
        else
          ++failures[m][i];
      }
  }
  result.cells.assign(options.methods.size(), std::vector<LrfSweepCell>(options.sizes.size()));
  for (size_t m = 0; m < options.methods.size(); ++m) {
    for (size_t i = 0; i < options.sizes.size(); ++i) {
      LrfSweepCell& cell = result.cells[m][i];
      const auto& runs = errors[m][i];
      cell.runs = static_cast<int>(runs.size());
      cell.failures = failures[m][i];
      if (runs.empty()) continue;
      for (const auto& [r, t] : runs) {
        cell.mean_rotation_deg += r / runs.size();
        cell.mean_translation_mm += t / runs.size();
      }
      for (const auto& [r, t] : runs) {
        cell.std_rotation_deg += std::pow(r - cell.mean_rotation_deg, 2) / runs.size();
        cell.std_translation_mm += std::pow(t - cell.mean_translation_mm, 2) / runs.size();
      }
      cell.std_rotation_deg = std::sqrt(cell.std_rotation_deg);
      cell.std_translation_mm = std::sqrt(cell.std_translation_mm);
    }
  }
  return result;
}

std::string FormatLrfSweepTable(const LrfSweepResult& result) {
  std::ostringstream out;
  out << "| observations |";
  for (LrfMethod m : result.methods)
    out << " " << LrfMethodName(m) << ": rotation [deg] | " << LrfMethodName(m)
        << ": translation [mm] |";
  out << "\n|---|";
  for (size_t m = 0; m < result.methods.size(); ++m) out << "---|---|";
  out << "\n";
  for (size_t i = 0; i < result.sizes.size(); ++i) {
    out << "| " << result.sizes[i] << " |";
    for (size_t m = 0; m < result.methods.size(); ++m) {
      const LrfSweepCell& c = result.cells[m][i];
      char text[160];
      std::snprintf(text, sizeof(text), " %.2f ± %.2f | %.1f ± %.1f%s |", c.mean_rotation_deg,
                    c.std_rotation_deg, c.mean_translation_mm, c.std_translation_mm,
                    c.failures ? (" (" + std::to_string(c.failures) + " failed)").c_str() : "");
      out << text;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace calibench
