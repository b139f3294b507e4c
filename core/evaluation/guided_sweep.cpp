#include "core/evaluation/guided_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "core/base/parallel.h"
#include "core/estimation/uncertainty.h"

namespace calibench {

bool GuidedSweepOptions::Check(std::string* why) const {
  if (!sim.Check(why) || !goal.Check(why) || !stop.Check(why) || !guidance.Check(why) ||
      !pipeline.Check(why))
    return false;
  if (seeds < 1) return *why = "seeds must be >= 1", false;
  if (max_pairs < 3) return *why = "max_pairs must be >= 3", false;
  if (!(hand_translation_m >= 0 && hand_rotation_deg >= 0))
    return *why = "the hand's error must be >= 0", false;
  if (threads < 1) return *why = "threads must be >= 1", false;
  return true;
}

namespace {

// The pose as a hand holds it: the target pose moved by up to hand_translation_m per axis and
// turned by up to hand_rotation_deg. Drawn again only when the board would stand in a wall: a
// pose the hand pushes out of the image or out of the detector's reach is kept, and the pair it
// gives is lost, as it would be on site.
Pose AsHeld(const SimOptions& sim, const Pose& target, const GuidedSweepOptions& options,
            std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int attempt = 0; attempt < 50; ++attempt) {
    Pose held = target;
    held.translation() += options.hand_translation_m * Vec3(unit(rng), unit(rng), unit(rng));
    const Vec3 axis = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
    const double angle = options.hand_rotation_deg * kDegToRad * std::abs(unit(rng));
    held.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix() * target.linear();
    if (FitsInSimulatedRoom(sim, held)) return held;
  }
  return target;
}

// The sensors as guidance learns them from the pairs so far (the detector's reach too, as
// `advise` does), the distance range as the user gives it.
std::optional<SensorGeometry> SensorsFromData(const SimOptions& sim,
                                              const std::vector<LidarCloud>& clouds,
                                              const std::vector<PairFeatures>& features,
                                              const std::optional<SolverResult>& solution) {
  std::vector<const LidarCloud*> views;
  for (const LidarCloud& c : clouds) views.push_back(&c);
  std::string why;
  auto sensors = LearnSensorGeometry(sim.camera, sim.board, LearnBeamTable(views), features, &why);
  if (!sensors) return std::nullopt;
  sensors->min_distance_m = sim.min_distance_m;
  sensors->max_distance_m = sim.max_distance_m;
  sensors->reach = LearnDetectionReach(
      sim.camera, sim.board, features,
      solution ? std::optional<Pose>(solution->cam_from_lidar) : std::nullopt, {});
  return sensors;
}

// A simulated pair through the pipeline's steps, the LiDAR side from the seed a brush would give.
PairFeatures SimulatedPairFeatures(const Dataset& dataset, const SimulatedPair& pair,
                                   const std::string& id, const PipelineOptions& pipeline) {
  PairFeatures f;
  f.id = id;
  std::string lidar_failure;
  BoardHint hint;
  hint.seed = pair.seed;
  f.lidar = ExtractLidarFeatures(dataset, pair.cloud, hint, pipeline, &lidar_failure);
  CameraFeatures camera = ExtractCameraFeatures(dataset, pair.image, pipeline);
  f.camera = std::move(camera.observation);
  f.edge_width_px = camera.edge_width_px;
  SetStatusFromFeatures(&f, lidar_failure, camera.failure);
  return f;
}

}  // namespace

GuidedRun RunGuidedCapture(const GuidedSweepOptions& options, std::uint64_t seed, bool guided) {
  SimOptions sim = options.sim;
  sim.seed = seed;
  sim = ResolveSimOptions(sim);
  Dataset dataset;  // the camera and the target, as a dataset of this rig would hold them
  dataset.camera = sim.camera;
  dataset.target = sim.board;
  PipelineOptions pipeline = options.pipeline;
  pipeline.threads = 1;
  GuidedRun run;
  run.placement = guided ? "guided" : "random";
  run.seed = seed;
  std::mt19937_64 hand(seed * 7919 + 17);
  std::vector<PairFeatures> features;
  std::vector<LidarCloud> clouds;  // a few, for the LiDAR's rings
  std::vector<Pose> seen;
  std::optional<SolverResult> solution;
  for (int k = 0; k < options.max_pairs; ++k) {
    Pose cam_from_board = RandomPlacement(sim, k);
    if (guided) {
      std::optional<SensorGeometry> sensors = SensorsFromData(sim, clouds, features, solution);
      if (!sensors) {
        // Nothing learnt yet: the camera alone, the simulator's LiDAR for its rings.
        sensors = SensorGeometry{};
        sensors->camera = sim.camera;
        sensors->board = sim.board;
        sensors->lidar = MakeBeamTable(sim.lidar);
        sensors->min_distance_m = sim.min_distance_m;
        sensors->max_distance_m = sim.max_distance_m;
      }
      std::string why;
      const std::optional<SolverResult> usable =
          solution && solution->observability.well_constrained ? solution : std::nullopt;
      if (const auto next = NextBestPose(*sensors, usable, seen, options.goal, options.guidance,
                                         pipeline.solver, &why)) {
        cam_from_board = AsHeld(sim, next->cam_from_board, options, hand);
      }
    }
    seen.push_back(cam_from_board);
    SimulatedPair pair = SimulatePairAt(sim, cam_from_board, k);
    PairFeatures f = SimulatedPairFeatures(dataset, pair, std::to_string(k), pipeline);
    features.push_back(std::move(f));
    if (clouds.size() < 8 && features.back().status == PairStatus::kAccepted)
      clouds.push_back(std::move(pair.cloud));
    run.poses = k + 1;
    run.accepted += features.back().status == PairStatus::kAccepted;
    if (features.back().status != PairStatus::kAccepted)
      run.failures.push_back("pose " + std::to_string(k) + ": " + features.back().reason);
    if (run.accepted < 3) continue;
    const CalibrationOutcome outcome = SolveFromFeatures(features, pipeline);
    if (!outcome.solution) continue;
    solution = outcome.solution;
    const CaptureState state = JudgeCapture(*solution, run.accepted, options.goal, options.stop);
    run.sigma_t_mm = state.sigma_t_mm;
    run.sigma_r_deg = state.sigma_r_deg;
    if (state.done) {
      run.done = true;
      break;
    }
  }
  if (solution) {
    // Why the camera missed the boards it missed, as `advise` would say it now.
    std::vector<MissedBoard> missed;
    LearnDetectionReach(sim.camera, sim.board, features, solution->cam_from_lidar, {}, &missed);
    for (const MissedBoard& m : missed)
      for (std::string& failure : run.failures)
        if (failure.rfind("pose " + m.id + ":", 0) == 0) failure += " — " + m.words;
    run.error_t_mm =
        (solution->cam_from_lidar.translation() - sim.cam_from_lidar.translation()) * 1e3;
    run.error_r_deg =
        LogSO3(solution->cam_from_lidar.linear() * sim.cam_from_lidar.linear().transpose()) *
        kRadToDeg;
    run.within_goal =
        (run.error_t_mm.cwiseAbs().array() <= 3 * options.goal.translation_mm).all() &&
        (run.error_r_deg.cwiseAbs().array() <= 3 * options.goal.rotation_deg).all();
    run.within_sigma = (run.error_t_mm.cwiseAbs().array() <= 3 * run.sigma_t_mm.array()).all() &&
                       (run.error_r_deg.cwiseAbs().array() <= 3 * run.sigma_r_deg.array()).all();
  }
  return run;
}

GuidedSweepResult RunGuidedSweep(const GuidedSweepOptions& options,
                                 const std::function<void(const std::string&)>& log) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("guided sweep: " + why);
  GuidedSweepResult result;
  result.options = options;
  result.runs.resize(2 * options.seeds);
  ParallelFor(
      result.runs.size(), options.threads,
      [&](size_t i) {
        result.runs[i] = RunGuidedCapture(options, options.first_seed + i / 2, i % 2 == 0);
      },
      [&](int, size_t i) {  // under ParallelFor's lock
        if (!log) return;
        const GuidedRun& r = result.runs[i];
        char text[240];
        std::snprintf(text, sizeof(text),
                      "%s seed %llu: %s after %d poses (%d accepted), error %.1f mm / %.3f deg",
                      r.placement.c_str(), static_cast<unsigned long long>(r.seed),
                      r.done ? "done" : "not done", r.poses, r.accepted, r.error_t_mm.norm(),
                      r.error_r_deg.norm());
        log(text);
        for (const std::string& failure : r.failures) log("  " + failure);
      });
  return result;
}

std::string FormatGuidedSweepTable(const GuidedSweepResult& result) {
  const GuidedSweepOptions& o = result.options;
  char line[400];
  std::snprintf(line, sizeof(line),
                "goal: 1σ ≤ %.1f mm and %.3f deg per axis; %d seeds; at most %d poses; the hand "
                "within ±%.0f cm and %.0f deg\n\n",
                o.goal.translation_mm, o.goal.rotation_deg, o.seeds, o.max_pairs,
                o.hand_translation_m * 100, o.hand_rotation_deg);
  std::string out = line;
  out +=
      "| placement | median poses to done (range) | done | unusable poses (most in a run) | true "
      "error within 3× goal | within 3σ | median error (mm / deg) |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const char* placement : {"guided", "random"}) {
    std::vector<double> poses, error_t, error_r;
    int done = 0, within_goal = 0, within_sigma = 0, runs = 0;
    int held = 0, unusable = 0, most_unusable = 0;
    for (const GuidedRun& r : result.runs) {
      if (r.placement != placement) continue;
      ++runs;
      // A run never done counts as needing more than the cap (it sorts last in the median).
      poses.push_back(r.done ? r.poses : o.max_pairs + 1);
      done += r.done;
      held += r.poses;
      unusable += r.poses - r.accepted;
      most_unusable = std::max(most_unusable, r.poses - r.accepted);
      within_goal += r.done && r.within_goal;
      within_sigma += r.done && r.within_sigma;
      error_t.push_back(r.error_t_mm.norm());
      error_r.push_back(r.error_r_deg.norm());
    }
    auto median = [](std::vector<double> v) {
      if (v.empty()) return 0.0;
      std::sort(v.begin(), v.end());
      const size_t n = v.size();
      return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    };
    auto poses_text = [&](double value) {
      char text[24];
      if (value > o.max_pairs)
        std::snprintf(text, sizeof(text), "> %d", o.max_pairs);
      else
        std::snprintf(text, sizeof(text), "%.1f", value);
      return std::string(text);
    };
    const auto [fewest, most] = std::minmax_element(poses.begin(), poses.end());
    std::snprintf(line, sizeof(line),
                  "| %s | %s (%s-%s) | %d / %d | %d of %d, %.0f %% (%d) | %d / %d | %d / %d | "
                  "%.1f / %.3f |\n",
                  placement, poses_text(median(poses)).c_str(), poses_text(*fewest).c_str(),
                  poses_text(*most).c_str(), done, runs, unusable, held,
                  held > 0 ? 100.0 * unusable / held : 0.0, most_unusable, within_goal, done,
                  within_sigma, done, median(error_t), median(error_r));
    out += line;
  }
  return out;
}

}  // namespace calibench
