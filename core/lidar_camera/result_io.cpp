#include "core/lidar_camera/result_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/lidar_camera/result_intrinsics_json.h"
#include "core/lidar_camera/result_lidar.h"
#include "core/lidar_camera/time_offset.h"
#include "core/results/result_json.h"

namespace calibench {
using nlohmann::json;

namespace {

json Vec4ToJson(const Vec4& v) { return {v[0], v[1], v[2], v[3]}; }

json ResidualsAvailable(const CalibrationOutcome& outcome) {
  const ResidualCounts counts = CountResiduals(outcome);
  return {{"plane_pairs", counts.plane_pairs},
          {"edge_pairs", counts.edge_pairs},
          {"edge_points", counts.edge_points},
          {"edges_in_model", counts.edges_in_model},
          {"note", counts.note}};
}

// One entry per pair: status, where its board came from, both planes' figures and, when solved
// with, its residual, weight and edge points.
json PairsJson(const CalibrationOutcome& outcome) {
  const SolverResult& s = *outcome.solution;
  json pairs = json::array();
  size_t solved_index = 0;
  for (const PairFeatures& p : outcome.pairs) {
    json entry = PairEntryJson(p.id, p.status, p.reason);
    if (p.board_origin.source != BoardSource::kNone) {
      entry["lidar_board"] = {{"source", BoardSourceName(p.board_origin.source)},
                              {"confidence", p.board_origin.confidence}};
      if (!p.board_origin.detail.empty()) entry["lidar_board"]["found"] = p.board_origin.detail;
    }
    if (p.lidar) {
      entry["lidar_plane"] = Vec4ToJson(p.lidar->plane.Coefficients());
      entry["lidar_inliers"] = p.lidar->inliers.size();
      entry["lidar_rms_m"] = p.lidar->rms_m;
      entry["lidar_model"] = LidarGeometryName(p.lidar->lidar_model.geometry);
      // What the rings' ends showed of the sheet's edges (why a pair gave no edge points).
      const BoardEdgeEnds& ends = p.lidar->edge_ends;
      if (p.lidar->no_edge_search.empty())
        entry["lidar_ring_ends"] = {{"ends", ends.ends},
                                    {"edge_points", ends.edge_points},
                                    {"no_return_beyond_sheet", ends.no_return},
                                    {"return_not_behind_sheet", ends.not_behind}};
      else
        entry["lidar_ring_ends"] = {{"not_searched", p.lidar->no_edge_search}};
    }
    if (p.camera) {
      entry["camera_plane"] = Vec4ToJson(p.camera->plane.Coefficients());
      entry["camera_corners"] = p.camera->num_corners;
      entry["reprojection_rms_px"] = p.camera->reprojection_rms_px;
    }
    if (p.status == PairStatus::kAccepted && solved_index < s.residuals.size()) {
      entry["residual"] = Vec4ToJson(s.residuals[solved_index]);
      entry["robust_weight"] = s.robust_weights[solved_index];
      // Accepted, yet weighted as if left out: said, not left to be read off a number.
      entry["down_weighted"] = s.DownWeighted(solved_index);
      if (solved_index < s.pair_edge_points.size())
        entry["board_edge_points"] = s.pair_edge_points[solved_index];
      ++solved_index;
    }
    pairs.push_back(entry);
  }
  return pairs;
}

// `time_offset` {camera_minus_lidar_s, std_s, ...}, or null with `time_offset_why`.
void AddTimeOffsetJson(const TimeOffsetEstimate& offset, json* root_json) {
  json& root = *root_json;
  if (offset.camera_minus_lidar_s) {
    root["time_offset"] = {
        {"camera_minus_lidar_s", *offset.camera_minus_lidar_s},
        {"std_s", offset.std_s},
        {"given", offset.fixed},
        {"moving_pairs", offset.profiled_pairs},
        {"meaning",
         "a camera stamp minus the LiDAR clock's time of the same instant (+0.040: the camera's "
         "stamps are 40 ms late); std_s is in the pose's covariance too"}};
  } else {
    root["time_offset"] = nullptr;
    root["time_offset_why"] = offset.why;
  }
}

json ResultToJson(const CalibrationOutcome& outcome, const SolverOptions& options,
                  const ResultNames& names) {
  CALIBENCH_CHECK(outcome.solution.has_value());
  const SolverResult& s = *outcome.solution;
  json root = ResultHeaderJson(names, s.cam_from_lidar, s.covariance, s.observability);
  root["solver"] = {{"method", SolverMethodName(options.method)},
                    {"iterations", s.iterations},
                    {"converged", s.converged},
                    {"termination", TerminationToJson(s.termination)},
                    {"cost_history", s.cost_history},
                    {"cost_comparable_from", s.cost_comparable_from},
                    {"huber_delta", options.huber_delta},
                    {"board_edge_points", s.num_edge_residuals},
                    // What the data said about the noise models: 1 = they held.
                    {"plane_variance_factor", s.plane_variance_factor},
                    {"edge_variance_factor", s.edge_variance_factor},
                    {"covariance_inflation", s.covariance_inflation},
                    // The leave-one-pair-out check behind the reported σ (0 pairs = not run).
                    {"jackknife_pairs", s.jackknife_pairs},
                    {"jackknife_widened", s.jackknife_widened}};
  if (s.edge_dilation) {
    root["solver"]["board_edge_dilation"] = {
        {"value_m", s.edge_dilation->value_m},
        {"sigma_m", s.edge_dilation->sigma_m},
        {"spread_over_pairs_m", s.edge_dilation->spread_m},
        {"meaning",
         "how much larger than the sheet the LiDAR sees it, per side (mean of the "
         "pairs' estimates)"}};
  }
  auto offset_json = [](const RangeOffsetEstimate& offset) {
    return json{{"value_m", offset.value_m},
                {"sigma_m", offset.sigma_m},
                {"convention", "measured range = true range + value_m; subtract it to correct"},
                {"correlation_with_translation",
                 {offset.correlation_with_translation.x(), offset.correlation_with_translation.y(),
                  offset.correlation_with_translation.z()}},
                {"well_determined", offset.well_determined}};
  };
  if (s.range_offset) root["lidar_range_offset"] = offset_json(*s.range_offset);
  if (s.unmodelled_range_offset) {
    root["unmodelled_lidar_range_offset"] = offset_json(*s.unmodelled_range_offset);
    root["unmodelled_lidar_range_offset"]["meaning"] =
        "not estimated, yet significant in the data (score test at the solution); the pose does "
        "not include it: estimate it (--estimate-range-offset) or correct the clouds";
  }
  if (!s.intrinsics_covariance.isZero(0.0)) {
    json matrix = json::array();
    for (int r = 0; r < 6; ++r) {
      json row = json::array();
      for (int c = 0; c < 6; ++c) row.push_back(s.intrinsics_covariance(r, c));
      matrix.push_back(row);
    }
    root["covariance_from_intrinsics"] = {
        {"covariance_6x6", matrix},
        {"meaning",
         "the part of covariance_6x6 that the camera's intrinsics' covariance contributes "
         "(propagated through the solve; same convention); more pairs do not shrink it"}};
  }
  if (outcome.estimated_intrinsics || outcome.intrinsics_refinement)
    root["intrinsics"] = IntrinsicsJson(outcome);
  root["pairs"] = PairsJson(outcome);
  root["solver"]["residuals_available"] = ResidualsAvailable(outcome);
  if (json model = LidarModelJson(outcome); !model.is_null()) root["lidar_model"] = model;
  if (json noise = LidarNoiseJson(outcome); !noise.is_null()) root["lidar_noise"] = noise;
  if (json times = LidarTimesJson(outcome); !times.is_null()) root["lidar_times"] = times;
  AddTimeOffsetJson(outcome.time_offset, &root);
  return root;
}

}  // namespace

namespace {

// Why a solved pair gave no edge point, from what its LiDAR fit observed.
std::string NoEdgeCause(const PairFeatures& pair, bool down_weighted) {
  if (down_weighted) return "down-weighted to nothing";
  if (!pair.lidar->no_edge_search.empty()) return "not searched: " + pair.lidar->no_edge_search;
  const BoardEdgeEnds& ends = pair.lidar->edge_ends;
  if (ends.ends == 0) return "no ring holds two board returns";
  if (ends.no_return == ends.ends) return "no return beyond the sheet at any ring end";
  if (ends.edge_points > 0) return "its edge points fell outside the model";
  return "at the ring ends the next return lies in front of or on the board's plane, not behind "
         "it";
}

}  // namespace

ResidualCounts CountResiduals(const CalibrationOutcome& outcome) {
  CALIBENCH_CHECK(outcome.solution.has_value());
  const SolverResult& s = *outcome.solution;
  ResidualCounts counts;
  counts.edges_in_model = s.edges_in_model;
  // Per cause, the pairs without edges and their ring ends.
  struct Cause {
    std::string words;
    std::vector<std::string> pairs;
    int ring_ends = 0;
  };
  std::vector<Cause> causes;
  size_t solved_index = 0;
  for (const PairFeatures& p : outcome.pairs) {
    if (p.status != PairStatus::kAccepted || solved_index >= s.residuals.size()) continue;
    const size_t index = solved_index++;
    ++counts.plane_pairs;
    const int edges = index < s.pair_edge_points.size() ? s.pair_edge_points[index] : 0;
    counts.edge_points += edges;
    counts.edge_pairs += edges > 0;
    if (edges > 0 || !s.edges_in_model || !p.lidar) continue;
    const std::string cause = NoEdgeCause(p, s.DownWeighted(index));
    auto it = std::find_if(causes.begin(), causes.end(),
                           [&](const Cause& c) { return c.words == cause; });
    if (it == causes.end()) it = causes.insert(causes.end(), Cause{cause, {}, 0});
    it->pairs.push_back(p.id);
    if (!s.DownWeighted(index) && p.lidar->no_edge_search.empty())
      it->ring_ends += p.lidar->edge_ends.ends;
  }
  if (!s.edges_in_model) {
    counts.note = "the method (" + SolverMethodName(s.method) +
                  ") uses the board planes only, no board edges";
    return counts;
  }
  if (causes.empty()) return counts;
  std::string groups;
  for (const Cause& cause : causes) {
    // The first few pairs by name, the rest counted: a line, not a list of forty.
    std::string names;
    for (size_t k = 0; k < cause.pairs.size() && k < 6; ++k)
      names += (k ? ", " : "") + cause.pairs[k];
    if (cause.pairs.size() > 6) names += " and " + std::to_string(cause.pairs.size() - 6) + " more";
    groups += (groups.empty() ? "" : "; ") + names + ": " + cause.words;
    if (cause.ring_ends > 0) groups += " (" + std::to_string(cause.ring_ends) + " ring ends)";
  }
  if (counts.edge_pairs == 0)
    counts.note = "board edges unused, no pair gave an edge point (" + groups +
                  "): nothing shows where the sheet ends, so the pose rests on the planes alone "
                  "and the translation along the boards comes only from their different tilts";
  else
    counts.note = "no edge points in " + std::to_string(counts.plane_pairs - counts.edge_pairs) +
                  " of " + std::to_string(counts.plane_pairs) + " pairs (" + groups + ")";
  return counts;
}

void WriteResult(const std::filesystem::path& path, const CalibrationOutcome& outcome,
                 const SolverOptions& options, const ResultNames& names) {
  WriteResultJson(path, ResultToJson(outcome, options, names));
}

namespace {

// One line per pair: its status, both sides' figures and, when solved with, its residual.
void PrintPairs(const CalibrationOutcome& outcome, std::ostringstream& out) {
  char line[256];
  int accepted = 0, failed = 0;
  for (const PairFeatures& p : outcome.pairs) {
    accepted += p.status == PairStatus::kAccepted;
    failed += p.status == PairStatus::kFailed;
  }
  out << "pairs: " << outcome.pairs.size() << " (" << accepted << " accepted, " << failed
      << " failed)\n";
  size_t solved_index = 0;
  std::string down_weighted;  // the pairs the solve weighted as if left out, with their |e|
  for (const PairFeatures& p : outcome.pairs) {
    if (p.status == PairStatus::kFailed) {
      out << "  pair " << p.id << " failed: " << p.reason << "\n";
      continue;
    }
    if (!p.lidar || !p.camera) continue;
    std::snprintf(line, sizeof(line),
                  "  pair %-8s %-8s board %-13s %4.2f | lidar %5zu inliers rms %5.1f mm | camera "
                  "%3d corners rms %.2f px",
                  p.id.c_str(), PairStatusName(p.status).c_str(),
                  BoardSourceName(p.board_origin.source).c_str(), p.board_origin.confidence,
                  p.lidar->inliers.size(), p.lidar->rms_m * 1e3, p.camera->num_corners,
                  p.camera->reprojection_rms_px);
    out << line;
    if (outcome.solution && p.status == PairStatus::kAccepted &&
        solved_index < outcome.solution->residuals.size()) {
      const double residual = outcome.solution->residuals[solved_index].norm();
      std::snprintf(line, sizeof(line), " | |e| %.4f weight %.2f", residual,
                    outcome.solution->robust_weights[solved_index]);
      out << line;
      if (outcome.solution->DownWeighted(solved_index)) {
        out << " (down-weighted to nothing)";
        std::snprintf(line, sizeof(line), "%s%s (|e| %.4f)", down_weighted.empty() ? "" : ", ",
                      p.id.c_str(), residual);
        down_weighted += line;
      }
      ++solved_index;
    }
    out << "\n";
  }
  if (!down_weighted.empty())
    out << "down-weighted to nothing (robust weight < " << outcome.solution->negligible_weight
        << "): " << down_weighted
        << ": accepted, but in effect left out of the solve; their planes disagree with the "
           "others'. Look at these pairs, or reject them.\n";
}

// What the weighted model estimated besides the pose: board edges, range offset, widening.
void PrintModelFigures(const SolverResult& s, std::ostringstream& out) {
  char line[256];
  if (s.num_edge_residuals > 0 && s.edge_dilation) {
    std::snprintf(line, sizeof(line),
                  "board edges: the LiDAR sees the sheet %+.1f ± %.1f mm larger per side (beam "
                  "footprint; pairs spread %.1f mm)\n",
                  s.edge_dilation->value_m * 1e3, s.edge_dilation->sigma_m * 1e3,
                  s.edge_dilation->spread_m * 1e3);
    out << line;
  }
  if (s.range_offset) {
    const Vec3& c = s.range_offset->correlation_with_translation;
    std::snprintf(line, sizeof(line),
                  "LiDAR range offset: %+.1f ± %.1f mm (measured = true + offset; correlation "
                  "with translation x/y/z %.2f %.2f %.2f)%s\n",
                  s.range_offset->value_m * 1e3, s.range_offset->sigma_m * 1e3, c.x(), c.y(), c.z(),
                  s.range_offset->well_determined ? "" : " NOT well determined");
    out << line;
  }
  if (s.unmodelled_range_offset) {
    std::snprintf(line, sizeof(line),
                  "WARNING: the data shows a LiDAR range offset of %+.1f ± %.1f mm that this "
                  "solve left out; rerun with --estimate-range-offset (or correct the clouds)\n",
                  s.unmodelled_range_offset->value_m * 1e3,
                  s.unmodelled_range_offset->sigma_m * 1e3);
    out << line;
  }
  // Which widening happened, in words whose numbers say it: the jackknife's covariance replaces
  // the model's when the pairs scatter more than their noise says; the sandwich only scales it.
  if (s.jackknife_widened) {
    out << "covariance from the pairs' leave-one-out spread (widened for the few pairs): they "
           "scatter more than the noise models say";
    if (s.covariance_inflation >= 1.005) {
      std::snprintf(line, sizeof(line), ", up to %.2fx their variance", s.covariance_inflation);
      out << line;
    }
    out << "\n";
  } else if (s.covariance_inflation >= 1.005) {
    std::snprintf(line, sizeof(line),
                  "covariance widened up to %.2fx (variance) by the spread over the pairs: the "
                  "noise models underestimate this data\n",
                  s.covariance_inflation);
    out << line;
  }
}

// What the camera's intrinsics did: refined with the extrinsic, or their covariance carried.
void PrintIntrinsics(const CalibrationOutcome& outcome, std::ostringstream& out) {
  char line[320];
  const SolverResult& s = *outcome.solution;
  if (const auto& r = outcome.intrinsics_refinement) {
    if (!r->failure.empty()) {
      out << "intrinsics NOT refined: " << r->failure << " (the camera file's are used)\n";
    } else {
      const std::vector<std::string> names = IntrinsicParameterNames(r->after);
      const std::vector<double> before = IntrinsicParameters(r->before);
      const std::vector<double> after = IntrinsicParameters(r->after);
      const size_t n = after.size();
      std::snprintf(line, sizeof(line),
                    "intrinsics refined with the extrinsic (--refine-intrinsics): %d pairs, %d "
                    "corners, %d edge points, %d iterations%s; corner RMS %.3f px\n",
                    r->pairs, r->corners, r->edge_points, r->iterations,
                    r->converged ? "" : " (NOT converged)", r->corner_rms_px);
      out << line;
      for (size_t i = 0; i < n; ++i) {
        if (i < r->refined.size() && !r->refined[i]) {
          std::snprintf(line, sizeof(line), "  %-3s %12.6g (held)\n", names[i].c_str(), after[i]);
        } else {
          const double sigma = std::sqrt(std::max(0.0, r->after.covariance[i * n + i]));
          std::snprintf(line, sizeof(line), "  %-3s %12.6g -> %12.6g +- %.3g  (moved %.1f sigma)\n",
                        names[i].c_str(), before[i], after[i], sigma,
                        sigma > 0 ? std::abs(after[i] - before[i]) / sigma : 0.0);
        }
        out << line;
      }
    }
  }
  if (!s.intrinsics_covariance.isZero(0.0)) {
    const Vec3 t = s.intrinsics_covariance.diagonal().head<3>().cwiseSqrt() * 1e3;
    const Vec3 r = s.intrinsics_covariance.diagonal().tail<3>().cwiseSqrt() * kRadToDeg;
    std::snprintf(line, sizeof(line),
                  "the intrinsics' covariance is in the std above: alone it gives translation "
                  "[mm] %.2f %.2f %.2f, rotation [deg] %.3f %.3f %.3f (more pairs do not shrink "
                  "it)\n",
                  t.x(), t.y(), t.z(), r.x(), r.y(), r.z());
    out << line;
  }
}

// Iterations, convergence and the observability verdict.
void PrintConvergence(const SolverResult& s, std::ostringstream& out) {
  char line[256];
  // Costs compare only under the same weights: from the last re-weighting (outliers gated,
  // variance factors re-estimated) on.
  const int from = s.cost_comparable_from;
  if (from == 0)
    std::snprintf(line, sizeof(line), "; cost %.3e -> %.3e\n", s.cost_history.front(),
                  s.cost_history.back());
  else
    std::snprintf(line, sizeof(line),
                  "; cost %.3e -> %.3e from iteration %d, when the pairs were last re-weighted\n",
                  s.cost_history[from], s.cost_history.back(), from);
  out << "solver: " << s.iterations << " iterations, " << s.termination.Describe() << line;
  if (s.observability.well_constrained) {
    out << "observability: well constrained\n";
  } else {
    out << "observability: NOT well constrained; weak directions:\n";
    for (const auto& d : s.observability.weak_directions) out << "  - " << d << "\n";
  }
}

}  // namespace

std::string FormatSummary(const CalibrationOutcome& outcome, const ResultNames& names) {
  std::ostringstream out;
  PrintPairs(outcome, out);
  if (!outcome.background_note.empty())
    out << "board detection without a background model: " << outcome.background_note << "\n";
  if (!outcome.solution) {
    out << "no calibration: " << outcome.failure << "\n";
    return out.str();
  }
  const SolverResult& s = *outcome.solution;
  out << FormatTransform(names, s.cam_from_lidar, s.covariance);
  if (const std::string model = DescribeLidarModel(outcome); !model.empty()) out << model << "\n";
  if (const std::string noise = DescribeLearnedLidarNoise(outcome); !noise.empty())
    out << noise << "\n";
  if (const std::string times = DescribeLidarTimes(outcome); !times.empty()) out << times << "\n";
  if (outcome.time_offset.moving_pairs > 0 || outcome.time_offset.fixed)
    out << DescribeTimeOffset(outcome.time_offset) << "\n";
  const ResidualCounts counts = CountResiduals(outcome);
  out << "residuals: board planes from " << counts.plane_pairs << " pairs";
  if (counts.edges_in_model)
    out << ", board edges from " << counts.edge_pairs << " pairs (" << counts.edge_points
        << " crossings of the sheet's edges)";
  out << "\n";
  if (!counts.note.empty()) out << "  " << counts.note << "\n";
  PrintModelFigures(s, out);
  PrintIntrinsics(outcome, out);
  PrintConvergence(s, out);
  return out.str();
}

}  // namespace calibench
