// What a result says of its LiDAR: the noise model each pair's plane was fitted with, and the
// noise learned from the boards' returns (core/target/lidar_noise.h).
#include "core/lidar_camera/result_lidar.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/lidar_camera/result_io.h"

namespace calibench {
using nlohmann::json;

namespace {

// Per LiDAR model, the pairs fitted with it (in the pairs' order) and the first one's reason.
struct ModelGroup {
  LidarGeometry geometry;
  std::vector<std::string> pairs;
  std::string why;
  bool forced = false;
  // A model without rays from the origin whose planes were fitted along each return's own ray
  // (the cloud carried viewpoints): FitPlaneRangeMl alone fills a fit's range sums.
  bool given_rays = false;
  // Board-only crops fitted along the rays (the held-out pairs chose them over point-to-plane).
  bool crop = false;
};

std::vector<ModelGroup> GroupByLidarModel(const CalibrationOutcome& outcome) {
  std::vector<ModelGroup> groups;
  for (const PairFeatures& p : outcome.pairs) {
    if (!p.lidar) continue;
    const LidarGeometryVerdict& model = p.lidar->lidar_model;
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const ModelGroup& g) { return g.geometry == model.geometry; });
    if (it == groups.end())
      it = groups.insert(groups.end(), {model.geometry, {}, model.why, model.forced});
    it->pairs.push_back(p.id);
    it->given_rays |= !RaysFromOrigin(model.geometry) && p.lidar->range_moments.count > 0;
    it->crop |= p.lidar->no_edge_search == kBoardOnlyCropNoEdges;
  }
  return groups;
}

std::string ModelMeaning(LidarGeometry geometry, bool given_rays, bool crop) {
  if (crop && RaysFromOrigin(geometry))
    return "planes fitted on the ranges along the rays of board-only crops: ring biases where "
           "their elevations fall into rings, no board edges (a crop ends where it was cut)";
  if (given_rays)
    return "planes fitted on the ranges along each return's own ray (from the viewpoint the cloud "
           "gives it, or from the mirror's position estimated from the scan), no ring biases or "
           "board edges";
  if (geometry == LidarGeometry::kSpinning)
    return "planes fitted on the ranges along the rays, with ring biases and board edges";
  if (geometry == LidarGeometry::kNonRepetitive)
    return "planes fitted on the ranges along the rays, no rings: no ring biases; board edges "
           "where the beam's path crosses the sheet's border";
  if (geometry == LidarGeometry::kSegment)
    return "planes fitted point-to-plane (isotropic, their own covariance, widened by a range bias "
           "per ring where the returns' elevations fall into rings), no board edges";
  return "planes fitted point-to-plane (isotropic, their own covariance), no ring biases or board "
         "edges";
}

// The LiDAR's noise learned from the accepted pairs' boards fitted along their rays.
LidarNoiseEstimate LearnedLidarNoise(const CalibrationOutcome& outcome) {
  std::vector<RangeResidualMoments> boards;
  for (const PairFeatures& p : outcome.pairs)
    if (p.status == PairStatus::kAccepted && p.lidar && p.lidar->range_moments.count > 0)
      boards.push_back(p.lidar->range_moments);
  return EstimateLidarNoise(boards);
}

json NoiseJson(const LidarNoiseEstimate& e) {
  return {{"boards", e.boards},
          {"returns", e.returns},
          {"range_sigma_m",
           {{"median", e.range_sigma_median_m},
            {"min", e.range_sigma_min_m},
            {"max", e.range_sigma_max_m}}},
          {"angular_sigma_deg", e.angular_sigma_rad * kRadToDeg},
          {"angular_sigma_upper_deg", std::isfinite(e.angular_sigma_upper_rad)
                                          ? json(e.angular_sigma_upper_rad * kRadToDeg)
                                          : json(nullptr)},
          {"angular_resolved", e.angular_resolved},
          {"equal_weight_efficiency_min", e.equal_weight_efficiency_min},
          {"meaning",
           "learned from the accepted boards' range residuals along their rays: variance = "
           "range_sigma^2 (per board) + (angular_sigma * range * tan(incidence))^2; "
           "angular_sigma_upper_deg is a 95% bound"}};
}

// The accepted boards' returns in time (LidarPlaneFit::inlier_times_s): per pair with times, its
// span and its centre after the cloud's stamp.
struct BoardTimes {
  int accepted = 0;  // accepted pairs with a LiDAR fit
  std::vector<double> spans_s, centres_s;
};

BoardTimes AcceptedBoardTimes(const CalibrationOutcome& outcome) {
  BoardTimes times;
  for (const PairFeatures& p : outcome.pairs) {
    if (p.status != PairStatus::kAccepted || !p.lidar) continue;
    ++times.accepted;
    const std::vector<float>& t = p.lidar->inlier_times_s;
    if (t.empty()) continue;
    const auto [low, high] = std::minmax_element(t.begin(), t.end());
    times.spans_s.push_back(*high - *low);
    times.centres_s.push_back(0.5 * (*high + *low));
  }
  return times;
}

double MedianOf(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

json LidarTimesJson(const CalibrationOutcome& outcome) {
  const BoardTimes times = AcceptedBoardTimes(outcome);
  if (times.accepted == 0) return nullptr;
  json out = {{"pairs", times.accepted}, {"pairs_with_point_times", times.spans_s.size()}};
  if (!times.spans_s.empty()) {
    out["board_span_s"] = {{"median", MedianOf(times.spans_s)},
                           {"max", *std::max_element(times.spans_s.begin(), times.spans_s.end())}};
    out["board_centre_after_stamp_s"] = {{"median", MedianOf(times.centres_s)}};
  }
  out["meaning"] =
      "each board's LiDAR returns in time (the clouds' per-point times, seconds after each pair's "
      "lidar_stamp_ns); a pair without them is taken as seen at its stamp";
  return out;
}

std::string DescribeLidarTimes(const CalibrationOutcome& outcome) {
  const BoardTimes times = AcceptedBoardTimes(outcome);
  if (times.accepted == 0) return "";
  if (times.spans_s.empty())
    return "LiDAR times: the clouds carry no per-point times; each board is taken as seen at its "
           "cloud's stamp";
  char text[256];
  std::snprintf(text, sizeof(text),
                "LiDAR times: %zu of %d boards' returns carry their own times; a board's returns "
                "span %.1f ms (median; longest %.1f ms), centred %+.1f ms after their cloud's "
                "stamp (median)",
                times.spans_s.size(), times.accepted, MedianOf(times.spans_s) * 1e3,
                *std::max_element(times.spans_s.begin(), times.spans_s.end()) * 1e3,
                MedianOf(times.centres_s) * 1e3);
  std::string words = text;
  if (static_cast<int>(times.spans_s.size()) < times.accepted)
    words += "; the others are taken as seen at their stamps";
  return words;
}

json LidarModelJson(const CalibrationOutcome& outcome) {
  const std::vector<ModelGroup> groups = GroupByLidarModel(outcome);
  if (groups.empty()) return nullptr;
  // The model most pairs were fitted with leads; every model's count follows.
  const ModelGroup& main = *std::max_element(
      groups.begin(), groups.end(),
      [](const ModelGroup& a, const ModelGroup& b) { return a.pairs.size() < b.pairs.size(); });
  json counts = json::object();
  for (const ModelGroup& g : groups) counts[LidarGeometryName(g.geometry)] = g.pairs.size();
  json model = {{"geometry", LidarGeometryName(main.geometry)},
                {"why", main.why},
                {"forced", main.forced},
                {"meaning", ModelMeaning(main.geometry, main.given_rays, main.crop)},
                {"pairs", counts}};
  if (const auto& e = outcome.lidar_model_evidence) {
    json candidates = json::array();
    for (const LidarModelCandidate& c : e->candidates)
      candidates.push_back({{"geometry", LidarGeometryName(c.geometry)},
                            {"along_rays", c.along_rays},
                            {"heldout_rms_m", std::isfinite(c.heldout_rms_m) ? json(c.heldout_rms_m)
                                                                             : json(nullptr)},
                            {"heldout_pairs", c.heldout_pairs}});
    model["evidence"] = {
        {"criterion", e->criterion},
        {"candidates", candidates},
        {"chosen", LidarGeometryName(e->chosen)},
        {"margin", std::isfinite(e->margin) ? json(e->margin) : json(nullptr)},
        {"significance_z",
         std::isfinite(e->significance_z) ? json(e->significance_z) : json(nullptr)},
        {"tie", e->tie},
        {"switched_pairs", e->switched_pairs}};
  }
  return model;
}

json LidarNoiseJson(const CalibrationOutcome& outcome) {
  const LidarNoiseEstimate noise = LearnedLidarNoise(outcome);
  return noise.boards > 0 ? NoiseJson(noise) : json(nullptr);
}

std::string DescribeLidarModel(const CalibrationOutcome& outcome) {
  const std::vector<ModelGroup> groups = GroupByLidarModel(outcome);
  std::string text;
  for (const ModelGroup& g : groups) {
    text += text.empty() ? "LiDAR model: " : "; ";
    text += LidarGeometryName(g.geometry) + " for ";
    if (groups.size() == 1) {
      text += "all " + std::to_string(g.pairs.size()) + " pairs";
    } else {
      text += std::to_string(g.pairs.size()) + " pairs (";
      for (size_t k = 0; k < g.pairs.size() && k < 5; ++k) text += (k ? ", " : "") + g.pairs[k];
      text += g.pairs.size() > 5 ? ", ...)" : ")";
    }
    text += " (" + g.why + "): " + ModelMeaning(g.geometry, g.given_rays, g.crop);
  }
  if (outcome.lidar_model_evidence && !text.empty())
    text += ". " + outcome.lidar_model_evidence->Describe();
  return text;
}

std::string DescribeLearnedLidarNoise(const CalibrationOutcome& outcome) {
  const LidarNoiseEstimate estimate = LearnedLidarNoise(outcome);
  if (estimate.boards > 0) return DescribeLidarNoise(estimate);
  const bool any_fit = std::any_of(outcome.pairs.begin(), outcome.pairs.end(), [](const auto& p) {
    return p.status == PairStatus::kAccepted && p.lidar.has_value();
  });
  // A swept scanner's or a segment's planes are fitted point-to-plane: no ray to measure along.
  return any_fit ? "LiDAR noise: each plane's own point-to-plane scatter (its model has no rays "
                   "from one origin, so no range or angular term is learned over the boards)"
                 : "";
}

}  // namespace calibench
