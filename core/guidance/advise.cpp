#include "core/guidance/advise.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/guidance/meter_json.h"
#include "core/io/cloud_io.h"

namespace calibench {

bool AdviseOptions::Check(std::string* why) const {
  if (!goal.Check(why) || !stop.Check(why) || !guidance.Check(why) || !preflight.Check(why) ||
      !pipeline.Check(why))
    return false;
  if (min_distance_m < 0 || max_distance_m < 0 ||
      (max_distance_m > 0 && !(max_distance_m > min_distance_m)))
    return *why = "the distance range must satisfy 0 <= min < max (0 = from the data)", false;
  if (clouds_for_beams < 1) return *why = "clouds_for_beams must be >= 1", false;
  return true;
}

namespace {

// Each pair's cloud − image stamp (seconds) from the import.json `calibench import` writes beside
// the manifest; empty when there is none (a folder of files has no stamps).
std::map<std::string, double> StampOffsets(const Dataset& dataset) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path folder =
      fs::is_directory(dataset.manifest, error) ? dataset.manifest : dataset.manifest.parent_path();
  std::map<std::string, double> offsets;
  std::ifstream in(folder / "import.json");
  if (!in) return offsets;
  const nlohmann::json record = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!record.is_object() || record.value("format", "") != "calibench.import.v1" ||
      !record.contains("pairs") || !record["pairs"].is_array())
    return offsets;
  for (const nlohmann::json& pair : record["pairs"]) {
    if (!pair.is_object() || !pair.contains("id") || !pair["id"].is_string() ||
        !pair.contains("cloud_stamp_ns") || !pair["cloud_stamp_ns"].is_number_integer() ||
        !pair.contains("image_stamp_ns") || !pair["image_stamp_ns"].is_number_integer())
      continue;
    offsets[pair["id"].get<std::string>()] =
        1e-9 * static_cast<double>(pair["cloud_stamp_ns"].get<std::int64_t>() -
                                   pair["image_stamp_ns"].get<std::int64_t>());
  }
  return offsets;
}

// Up to `count` accepted pairs' clouds, read again to learn the LiDAR's rings from.
std::vector<LidarCloud> RingClouds(const Dataset& dataset, const std::vector<PairFeatures>& pairs,
                                   int count) {
  std::vector<LidarCloud> clouds;
  for (const PairFeatures& p : pairs) {
    if (p.status != PairStatus::kAccepted || static_cast<int>(clouds.size()) >= count) continue;
    for (const PairEntry& entry : dataset.pairs) {
      if (entry.id != p.id) continue;
      try {
        clouds.push_back(LoadCloud(entry.cloud));
      } catch (const std::exception&) {
        // Unreadable now: the pair's own status already says so, or it changed since.
      }
    }
  }
  return clouds;
}

// The camera from every pair's corners (those the pipeline posed: the board found), as
// `calibench intrinsics` would calibrate it.
void EstimateIntrinsicsFromPairs(const CameraModel& camera, const std::vector<PairFeatures>& pairs,
                                 const IntrinsicsOptions& options, CaptureAdvice* advice) {
  std::vector<IntrinsicsView> views;
  for (const PairFeatures& p : pairs)
    if (p.camera && !p.camera->corners.pixels.empty()) views.push_back({p.id, p.camera->corners});
  IntrinsicsOptions wanted = options;
  wanted.model = camera.type;
  try {
    advice->intrinsics = CalibrateIntrinsics(views, camera.width, camera.height, wanted);
  } catch (const std::invalid_argument& e) {
    advice->intrinsics_failure = e.what();
  }
}

// Pre-flight, pair by pair in capture order, against the pairs before it: each pair's findings
// into advice->pairs; a pair a check rejects leaves the solve, with the finding as its reason.
// Returns the pairs as judged; *rejected_any says whether one was rejected.
std::vector<PairFeatures> PreflightPairs(const Dataset& dataset, const CalibrationOutcome& outcome,
                                         const AdviseOptions& options, CaptureAdvice* advice,
                                         bool* rejected_any) {
  std::vector<PairFeatures> pairs = outcome.pairs;
  std::vector<PairFeatures> earlier;
  const std::map<std::string, double> stamp_offsets = StampOffsets(dataset);
  *rejected_any = false;
  for (PairFeatures& p : pairs) {
    PairAdvice pair;
    PreflightInputs in;
    in.pair = &p;
    in.camera = &dataset.camera;
    in.board = &dataset.target;
    if (outcome.solution) in.cam_from_lidar = outcome.solution->cam_from_lidar;
    in.earlier = &earlier;
    in.pipeline = &options.pipeline;
    if (const auto it = stamp_offsets.find(p.id); it != stamp_offsets.end())
      in.stamp_offset_s = it->second;
    pair.findings = PreflightPair(in, options.preflight);
    for (const PreflightFinding& f : pair.findings) {
      if (f.severity != PreflightSeverity::kReject || p.status != PairStatus::kAccepted) continue;
      p.status = PairStatus::kRejected;
      p.reason = "pre-flight: " + f.words;
      *rejected_any = true;
    }
    static_cast<PairStanding&>(pair) = p;  // where pre-flight left it
    advice->pairs.push_back(std::move(pair));
    earlier.push_back(p);
  }
  return pairs;
}

}  // namespace

CaptureAdvice AdviseCapture(const Dataset& dataset, const CalibrationOutcome& outcome,
                            const AdviseOptions& options) {
  CaptureAdvice advice;
  advice.goal = options.goal;
  bool rejected_any = false;
  const std::vector<PairFeatures> pairs =
      PreflightPairs(dataset, outcome, options, &advice, &rejected_any);
  advice.solution = outcome.solution;
  if (rejected_any) {
    const CalibrationOutcome again = SolveFromFeatures(pairs, options.pipeline);
    advice.solution = again.solution;
  }
  std::vector<Pose> seen;
  for (const PairFeatures& p : pairs) {
    if (p.status != PairStatus::kAccepted) continue;
    ++advice.pairs_used;
    if (p.camera) seen.push_back(p.camera->cam_from_board);
  }
  if (advice.solution)
    advice.state = JudgeCapture(*advice.solution, advice.pairs_used, options.goal, options.stop);
  GuidanceOptions guidance = options.guidance;
  if (options.estimate_intrinsics) {
    EstimateIntrinsicsFromPairs(dataset.camera, pairs, options.intrinsics, &advice);
    if (advice.intrinsics)
      guidance.intrinsics_cells_to_cover =
          EmptyCells(advice.intrinsics->coverage, dataset.camera.width, dataset.camera.height);
    if (!guidance.intrinsics_cells_to_cover.empty()) {
      // Board centres nearer the image's edges, where the empty cells are.
      guidance.image_columns = std::max(guidance.image_columns, 5);
      guidance.image_rows = std::max(guidance.image_rows, 5);
      guidance.distance_steps = std::max(guidance.distance_steps, 6);
    }
    if (advice.state && !(advice.intrinsics && advice.intrinsics->good)) advice.state->done = false;
  }
  // Where the camera missed a board the LiDAR placed: why, and the reach that guidance keeps to.
  std::vector<MissedBoard> missed;
  advice.reach = LearnDetectionReach(
      dataset.camera, dataset.target, pairs,
      advice.solution ? std::optional<Pose>(advice.solution->cam_from_lidar) : std::nullopt, {},
      &missed);
  for (const MissedBoard& m : missed)
    for (PairAdvice& pair : advice.pairs)
      if (pair.id == m.id) pair.findings.push_back({"reach", PreflightSeverity::kReject, m.words});
  if (advice.state && advice.state->done) return advice;
  const std::vector<LidarCloud> clouds = RingClouds(dataset, pairs, options.clouds_for_beams);
  std::vector<const LidarCloud*> cloud_views;
  for (const LidarCloud& c : clouds) cloud_views.push_back(&c);
  std::string why;
  auto sensors =
      LearnSensorGeometry(dataset.camera, dataset.target, LearnBeamTable(cloud_views), pairs, &why);
  if (!sensors) {
    advice.next_failure = why;
    return advice;
  }
  if (options.max_distance_m > 0) {
    sensors->min_distance_m = options.min_distance_m;
    sensors->max_distance_m = options.max_distance_m;
  }
  sensors->reach = advice.reach;
  // Guidance needs a solution that fixes all six degrees of freedom.
  std::optional<SolverResult> usable = advice.solution;
  if (usable && !usable->observability.well_constrained) usable.reset();
  advice.next = NextBestPose(*sensors, usable, seen, options.goal, guidance,
                             options.pipeline.solver, &advice.next_failure);
  return advice;
}

std::string DescribeCaptureProgress(const CaptureAdvice& advice) {
  std::string line =
      advice.state ? DescribeCaptureState(*advice.state, advice.goal)
                   : std::to_string(advice.pairs_used) + " pairs accepted: no calibration yet";
  if (advice.next) line += "; next: " + advice.next->words;
  return line;
}

std::string CaptureAdviceJson(const CaptureAdvice& advice) {
  nlohmann::json out = MeterJson(
      advice.pairs_used, advice.goal, "cam_from_lidar",
      advice.solution ? std::optional<Pose>(advice.solution->cam_from_lidar) : std::nullopt,
      advice.state, "no calibration yet: at least 3 accepted pairs with differently tilted boards");
  if (advice.next) {
    const PoseSuggestion& next = *advice.next;
    nlohmann::json n;
    n["lidar_from_board"] =
        next.lidar_from_board ? MatrixJson(next.lidar_from_board->matrix()) : nlohmann::json();
    n["cam_from_board"] = MatrixJson((next.cam_from_board * ShownFromBoardSpec()).matrix());
    n["words"] = next.words;
    if (next.lidar_from_board) {
      n["predicted_sigma_t_mm"] = VecJson(next.predicted_sigma_t_mm);
      n["predicted_sigma_r_deg"] = VecJson(next.predicted_sigma_r_deg);
      n["predicted_rings"] = next.feasibility.rings;
      n["predicted_points"] = next.feasibility.points;
    }
    n["usable_share"] = next.usable_share;
    n["tolerance"] = {{"translation_m", next.tolerance.translation_m},
                      {"rotation_deg", next.tolerance.rotation_deg},
                      {"usable_share", next.tolerance.usable_share},
                      {"words", next.tolerance.words}};
    out["next"] = n;
  } else {
    out["next"] = nullptr;
    if (!(advice.state && advice.state->done)) out["next_failure"] = advice.next_failure;
  }
  const DetectionReach& reach = advice.reach;
  auto measured = [](bool known, double value) {
    return known ? nlohmann::json(value) : nlohmann::json();
  };
  out["detection_reach"] = {
      {"min_square_px", measured(reach.min_square_px > 0, reach.min_square_px)},
      {"max_incidence_deg", measured(reach.max_incidence_deg < 90, reach.max_incidence_deg)},
      {"max_off_axis_deg", measured(reach.max_off_axis_deg < 180, reach.max_off_axis_deg)},
      {"boards_found", reach.boards_found},
      {"boards_missed", reach.boards_missed}};
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairAdvice& p : advice.pairs) {
    nlohmann::json findings = nlohmann::json::array();
    for (const PreflightFinding& f : p.findings)
      findings.push_back(
          {{"check", f.check},
           {"severity", f.severity == PreflightSeverity::kReject ? "reject" : "weak"},
           {"words", f.words}});
    pairs.push_back({{"name", p.id},
                     {"status", PairStatusName(p.status)},
                     {"reason", p.reason},
                     {"findings", findings}});
  }
  out["pairs"] = pairs;
  if (advice.intrinsics) {
    const IntrinsicsResult& r = *advice.intrinsics;
    nlohmann::json parameters = nlohmann::json::object(), sigmas = nlohmann::json::object();
    for (size_t i = 0; i < r.parameter_names.size(); ++i) {
      parameters[r.parameter_names[i]] = r.parameters[i];
      sigmas[r.parameter_names[i]] = r.sigmas[i];
    }
    out["intrinsics"] = {{"good", r.good},
                         {"verdict", r.verdict},
                         {"rms_px", r.rms_px},
                         {"parameters", parameters},
                         {"sigmas", sigmas},
                         {"cells_covered", r.coverage.cells_covered},
                         {"border_covered", r.coverage.border_covered},
                         {"missing", r.coverage.missing}};
  } else if (!advice.intrinsics_failure.empty()) {
    out["intrinsics"] = {{"good", false}, {"failure", advice.intrinsics_failure}};
  }
  return out.dump();
}

std::string FormatCaptureAdvice(const CaptureAdvice& advice) {
  std::string out;
  for (const PairAdvice& p : advice.pairs) {
    if (p.status != PairStatus::kAccepted)
      out += "pair " + p.id + ": " + PairStatusName(p.status) + ": " + p.reason + "\n";
    for (const PreflightFinding& f : p.findings)
      out += "pair " + p.id + ": " +
             (f.severity == PreflightSeverity::kReject ? "reject: " : "weak: ") + f.words + "\n";
  }
  if (advice.state) {
    out += DescribeCaptureState(*advice.state, advice.goal) + "\n";
  } else {
    out += std::to_string(advice.pairs_used) +
           " pairs accepted: no calibration yet (at least 3 with differently tilted boards)\n";
  }
  if (advice.intrinsics) {
    const IntrinsicsResult& r = *advice.intrinsics;
    char text[200];
    std::snprintf(text, sizeof(text),
                  "intrinsics (estimated from the pairs): fx %.1f +- %.2f, fy %.1f +- %.2f, cx "
                  "%.1f +- %.2f, cy %.1f +- %.2f px, RMS %.2f px: ",
                  r.parameters[0], r.sigmas[0], r.parameters[1], r.sigmas[1], r.parameters[2],
                  r.sigmas[2], r.parameters[3], r.sigmas[3], r.rms_px);
    out += text + r.verdict + "\n";
  } else if (!advice.intrinsics_failure.empty()) {
    out += "intrinsics not estimated yet: " + advice.intrinsics_failure + "\n";
  }
  if (advice.next) {
    out += "next pose: " + advice.next->words + "\n";
    if (advice.next->lidar_from_board) {
      char text[200], returns[64];
      const Feasibility& f = advice.next->feasibility;
      if (f.rings > 0)
        std::snprintf(returns, sizeof(returns), "%d rings, %d points", f.rings, f.points);
      else  // a ring-less LiDAR's rays
        std::snprintf(returns, sizeof(returns), "%d returns", f.points);
      std::snprintf(text, sizeof(text),
                    "  expected σ after it: %.1f/%.1f/%.1f mm, %.3f/%.3f/%.3f deg (%s on the "
                    "sheet)\n",
                    advice.next->predicted_sigma_t_mm.x(), advice.next->predicted_sigma_t_mm.y(),
                    advice.next->predicted_sigma_t_mm.z(), advice.next->predicted_sigma_r_deg.x(),
                    advice.next->predicted_sigma_r_deg.y(), advice.next->predicted_sigma_r_deg.z(),
                    returns);
      out += text;
    }
  } else if (!(advice.state && advice.state->done)) {
    out += "no next pose: " + advice.next_failure + "\n";
  }
  return out;
}

}  // namespace calibench
