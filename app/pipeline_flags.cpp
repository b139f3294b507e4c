#include "app/pipeline_flags.h"

#include <unistd.h>

#include <cstdio>
#include <functional>
#include <map>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <variant>

#include "app/commands.h"
#include "app/progress_listener.h"
#include "core/estimation/uncertainty.h"
#include "core/geometry/geometry.h"
#include "core/guidance/advise.h"
#include "core/lidar_camera/joint_intrinsics.h"
#include "core/lidar_camera/result_io.h"
#include "core/session/calibration_job.h"
#include "core/session/job.h"
#include "core/session/session.h"

namespace calibench::app {

namespace {

// One setting's flag, from its declaration (core/session/session.h, JobSettingFields). The method
// is a name, parsed by FinalizePipelineFlags.
void AddSettingFlag(CLI::App& app, const JobSettingField& setting, PipelineFlags& flags) {
  const std::string flag = "--" + std::string(setting.flag);
  const std::string words(setting.words);
  JobSettings& settings = flags.settings;
  std::visit(
      [&](auto slot) {
        auto& value = settings.*slot.setting;
        using Value = std::remove_reference_t<decltype(value)>;
        if constexpr (std::is_same_v<Value, SolverMethod>) {
          flags.method = SolverMethodName(value);
          app.add_option(flag, flags.method, words)->capture_default_str();
        } else if constexpr (std::is_same_v<Value, bool>) {
          app.add_flag(flag, value, words);
        } else {
          app.add_option(flag, value, words)->capture_default_str();
        }
      },
      setting.slot);
}

// A moving capture's clocks (core/lidar_camera/time_offset.h).
void AddTimeOffsetFlags(CLI::App& app, TimeOffsetOptions* offset) {
  app.add_option("--time-offset-search", offset->search_s,
                 "a waved board's capture (pairs with \"images\"): half-width of the "
                 "search for the camera's clock against the LiDAR's [s]")
      ->capture_default_str();
  app.add_option_function<double>(
      "--time-offset", [offset](double seconds) { offset->fixed_s = seconds; },
      "a waved board's capture: the camera's stamps minus the LiDAR's clock, known [s] "
      "(+0.04: the camera's stamps 40 ms late); not searched then. 0 pairs each sweep "
      "with the camera's boards at the same stamps");
}

}  // namespace

void AddPipelineFlags(CLI::App& app, PipelineFlags& flags, bool with_selection) {
  PipelineOptions& o = flags.options;
  // The settings' flags come from their declaration, each followed by the flags that belong
  // with it in the help.
  flags.settings = JobSettings::Of(o);
  const std::map<std::string_view, std::function<void()>> then = {
      {"max-iterations",
       [&] {
         app.add_flag_callback(
             "--no-board-edges", [&o] { o.solver.use_board_edges = false; },
             "weighted-ml: leave out the board-edge constraints (used by default for targets "
             "whose sheet size is given)");
         app.add_flag_callback(
             "--no-edge-dilation", [&o] { o.solver.estimate_edge_dilation = false; },
             "weighted-ml with board edges: do not estimate how much larger than the sheet the "
             "LiDAR sees it (the beam's footprint; estimated by default)");
       }},
      {"estimate-range-offset",
       [&] {
         app.add_option("--range-offset-prior-mm", flags.range_offset_prior_mm,
                        "weighted-ml: 1σ of the LiDAR range offset known before the data [mm] (0 "
                        "= none): estimated, a prior on it; left out, the bias it could cause is "
                        "in the reported σ")
             ->capture_default_str();
         app.add_flag("--refine-intrinsics{focal}", flags.refine_intrinsics,
                      "estimate the camera's intrinsics with the extrinsic in one joint problem "
                      "(corners, LiDAR planes and edges), then pose every pair under them: focal "
                      "(fx fy, the default: what the LiDAR's distances tell) | pinhole (+ cx cy) "
                      "| all (+ the distortion), as --refine-intrinsics=all; the result gets an "
                      "\"intrinsics\" entry with both cameras");
         app.add_flag_callback(
             "--ignore-intrinsics-covariance", [&o] { o.propagate_intrinsics = false; },
             "leave the camera file's intrinsics covariance (intrinsics_covariance) out of the "
             "extrinsic's sigma (it is carried into it by default)");
         app.add_flag_callback(
             "--no-jackknife", [&o] { o.solver.jackknife_covariance = false; },
             "weighted-ml: do not widen the reported covariance to the leave-one-pair-out "
             "spread");
         if (with_selection) {
           app.add_option("--pairs", flags.pairs, "comma-separated pair ids to use (default: all)");
           app.add_option("--initial-guess", flags.initial_guess,
                          "cam_from_lidar to start from: a result.json, or 16 comma-separated "
                          "numbers (row-major 4x4); default: closed form from the planes");
         }
         app.add_option("--threads", o.threads,
                        "workers (default: this machine's hardware threads; the result does not "
                        "depend on it)")
             ->capture_default_str();
       }},
      {"ransac-threshold",
       [&] {
         app.add_option("--ransac-seed", o.lidar_plane.seed, "RANSAC seed")->capture_default_str();
         app.add_option(
             "--lidar-model", flags.lidar_model,
             "the LiDAR's noise model: spinning (ranges along rays from one centre, rings: "
             "ring biases and board edges) | swept (a line scanner turned by a stage, rays "
             "from a moving mirror) | non-repetitive (Livox-class: ranges along rays from one "
             "centre, no rings) | segment (board-only clouds); swept and segment fit "
             "planes point-to-plane with their own covariance. Default: judged from each "
             "cloud (rings, cones of elevation, the returns' extent), said in the summary");
         app.add_flag_callback(
             "--no-board-growing", [&o] { o.grow_to_board = false; },
             "fit the LiDAR plane on the brushed / seeded returns only, instead of growing the "
             "region to the whole board (limited by the target's sheet size)");
         AddTimeOffsetFlags(app, &o.time_offset);
       }},
  };
  for (const JobSettingField& setting : JobSettingFields()) {
    AddSettingFlag(app, setting, flags);
    if (const auto next = then.find(setting.flag); next != then.end()) next->second();
  }
}

void AddGoalFlags(CLI::App& app, AdviseOptions* options) {
  app.add_option("--goal-mm", options->goal.translation_mm,
                 "goal: 1σ of the translation per axis [mm]")
      ->capture_default_str();
  app.add_option("--goal-deg", options->goal.rotation_deg,
                 "goal: 1σ of the rotation per axis [deg]")
      ->capture_default_str();
  app.add_option("--hand-tolerance-m", options->guidance.hand_tolerance_m,
                 "how far the person may miss the suggested pose, ± per axis [m]: the next pose "
                 "is one that stays usable within it")
      ->capture_default_str();
  app.add_option("--hand-tolerance-deg", options->guidance.hand_tolerance_deg,
                 "how far the person may turn the board from the suggested pose, at most [deg]")
      ->capture_default_str();
}

bool FinalizePipelineFlags(PipelineFlags& flags, std::string* why) {
  const auto method = ParseSolverMethod(flags.method);
  if (!method) {
    *why = "--method must be weighted-ml, ca2lib-gn or kim, not '" + flags.method + "'";
    return false;
  }
  flags.settings.method = *method;
  flags.settings.Apply(&flags.options);
  // As the flags say: a range offset asked of another method is refused (SolverOptions::Check,
  // below), not dropped as a session's choice is kept for its method (JobSettings::Apply).
  flags.options.solver.estimate_range_offset = flags.settings.estimate_range_offset;
  flags.options.solver.range_offset_prior_sigma_m = flags.range_offset_prior_mm * 1e-3;
  if (!flags.lidar_model.empty()) {
    const auto model = ParseLidarGeometry(flags.lidar_model);
    if (!model) {
      *why = "--lidar-model must be one of " + LidarGeometryNames() + ", not '" +
             flags.lidar_model + "'";
      return false;
    }
    flags.options.lidar_model = *model;
  }
  if (!flags.refine_intrinsics.empty()) {
    const auto which = ParseIntrinsicsToRefine(flags.refine_intrinsics);
    if (!which) {
      *why = "--refine-intrinsics must be focal, pinhole or all, not '" + flags.refine_intrinsics +
             "'";
      return false;
    }
    flags.options.refine_intrinsics = true;
    flags.options.intrinsics_to_refine = *which;
  }
  if (!flags.pairs.empty()) {
    std::stringstream ss(flags.pairs);
    std::string id;
    while (std::getline(ss, id, ','))
      if (!id.empty()) flags.options.pair_ids.push_back(id);
  }
  if (!flags.initial_guess.empty()) {
    if (flags.initial_guess.find(',') != std::string::npos) {
      std::stringstream ss(flags.initial_guess);
      std::string number;
      std::vector<double> values;
      while (std::getline(ss, number, ',')) {
        try {
          values.push_back(std::stod(number));
        } catch (const std::exception&) {
          *why = "--initial-guess: '" + number + "' is not a number";
          return false;
        }
      }
      if (values.size() != 16) {
        *why = "--initial-guess needs 16 numbers (row-major 4x4), got " +
               std::to_string(values.size());
        return false;
      }
      Mat4 m;
      for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = values[i];
      Pose pose = Pose::Identity();
      pose.linear() = NearestRotation(m.topLeftCorner<3, 3>());
      pose.translation() = m.topRightCorner<3, 1>();
      flags.options.initial_cam_from_lidar = pose;
    } else {
      flags.options.initial_cam_from_lidar = LoadResult(flags.initial_guess).cam_from_source;
    }
  }
  return flags.options.Check(why);
}

ProgressCallback StderrProgress(const std::string& verb) {
  const bool tty = isatty(fileno(stderr));
  return [tty, verb](int done, int total, const std::string& id) {
    std::fprintf(stderr, tty ? "\r[%d/%d] %s pair %s   " : "[%d/%d] %s pair %s\n", done, total,
                 verb.c_str(), id.c_str());
    if (tty && done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
    NotifyProgress(verb, done, total, id);
  };
}

PairEdits ApplySessionFlag(const std::string& session_path, std::string* dataset_path,
                           PipelineOptions* options) {
  if (session_path.empty()) return {};
  const Session session = LoadSession(session_path);
  RefuseLrfSession(session, session_path);
  if (dataset_path->empty()) *dataset_path = session.dataset.string();
  session.settings.Apply(options);
  return EditsFromSession(session);
}

void PrintErrorAgainstTruth(const PoseError& error, const Mat6& covariance,
                            const Pose& cam_from_source) {
  const Vec3 st = TranslationStd(covariance, cam_from_source) * 1000.0;
  const Vec3 sr = RotationStdDeg(covariance, cam_from_source);
  std::printf("error against ground truth: translation %.2f mm, rotation %.3f deg\n",
              error.translation_m * 1000.0, error.rotation_rad * kRadToDeg);
  std::printf("reported std: translation %.2f mm, rotation %.3f deg (root of summed variances)\n",
              st.norm(), sr.norm());
}

namespace {

// "\n  pair ID: reason" per unreadable pair of each verdict, a rig's named by camera.
std::string UnreadableLines(const std::vector<JobVerdict>& verdicts,
                            const std::vector<std::string>& cameras) {
  std::string lines;
  for (size_t c = 0; c < verdicts.size(); ++c)
    lines += verdicts[c].Unreadable(verdicts.size() > 1 ? "camera " + cameras[c] + " " : "");
  return lines;
}

}  // namespace

int SayVerdicts(const std::vector<JobVerdict>& verdicts, const std::vector<std::string>& cameras,
                const std::string& command, const std::string& data) {
  const std::string prefix = "calibench " + command + ": ";
  const std::string unreadable = UnreadableLines(verdicts, cameras);
  if (verdicts.empty() || !verdicts.front().solved) {
    std::fprintf(stderr, "%sno calibration for %s: %s%s%s\n", prefix.c_str(), data.c_str(),
                 verdicts.empty() ? "no camera" : verdicts.front().failure.c_str(),
                 unreadable.empty() ? "" : "; unreadable:", unreadable.c_str());
    return unreadable.empty() ? kNoCalibration : kInputError;
  }
  for (size_t c = 0; c < verdicts.size(); ++c) {
    const JobVerdict& verdict = verdicts[c];
    if (!verdict.ground_truth) continue;
    if (verdicts.size() > 1) std::printf("camera %s:\n", cameras[c].c_str());
    PrintErrorAgainstTruth(ComputePoseError(verdict.cam_from_source, *verdict.ground_truth),
                           verdict.covariance, verdict.cam_from_source);
  }
  if (!unreadable.empty()) {
    std::fprintf(stderr,
                 "%ssome pair files could not be read; the result uses the remaining pairs:%s\n",
                 prefix.c_str(), unreadable.c_str());
    return kInputError;
  }
  std::string weak;
  for (size_t c = 0; c < verdicts.size(); ++c)
    if (!verdicts[c].well_constrained) weak += (weak.empty() ? " (camera " : ", ") + cameras[c];
  if (!weak.empty()) {
    std::fprintf(stderr,
                 "%sthe result is NOT well constrained%s (weak directions listed above): add "
                 "pairs with the target tilted and turned differently\n",
                 prefix.c_str(), verdicts.size() > 1 ? (weak + ")").c_str() : "");
    return kNotConstrained;
  }
  return kOk;
}

int SolveAndSay(Job& job, const std::string& command, const std::string& out_path) {
  const JobVerdict verdict = job.Calibrate();
  std::printf("%s", verdict.summary.c_str());
  if (verdict.solved && !out_path.empty()) {
    job.WriteResultFile(out_path);
    std::printf("wrote %s\n", out_path.c_str());
  }
  return SayVerdicts({verdict}, {""}, command, job.manifest().string());
}

int CalibrateAndReport(const Dataset& dataset, const PipelineOptions& options,
                       const std::string& out_path, CalibrationOutcome* outcome_out,
                       const PairEdits& edits, const std::optional<IntrinsicsResult>& estimated) {
  // The job every front end runs (core/session/calibration_job.h), all pairs at once.
  CalibrationJobOptions job_options;
  job_options.advise.pipeline = options;
  job_options.estimated_intrinsics = estimated;
  CalibrationJob job(dataset, job_options, edits);
  job.ExtractAll(StderrProgress("extracted"));
  const int code = SolveAndSay(job, "calibrate", out_path);
  if (outcome_out) *outcome_out = *job.outcome();
  return code;
}

}  // namespace calibench::app
