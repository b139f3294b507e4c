// Sequential plane extraction in the depth cloud (papers/lrf-depth-camera-vboard.txt Fig. 7 (c)):
// RANSAC with one point and its local normal per draw, each plane's largest connected set of
// inliers, noise tails dropped, coplanar pieces merged.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/lrf/depth_cloud.h"

namespace calibench::depth {

namespace {

// Points RANSAC looks at (a random subset of the live points): plenty to find a surface of the
// min_inliers_per_face the target's faces have; the connected inliers among all points then
// refine it (ConnectedInliers). RANSAC's cost is linear in it.
constexpr size_t kRansacSamplePoints = 1500;

// The RANSAC sample of the live points, and one threshold for it: that of the nearer quarter,
// since leftovers far away (where the threshold is wide) must not let a plane slice through
// several near surfaces and win.
RansacSample DrawSample(const DepthCloud& cloud, std::vector<int> live, std::mt19937_64* rng,
                        const DepthFeatureOptions& options) {
  std::shuffle(live.begin(), live.end(), *rng);
  live.resize(std::min(live.size(), kRansacSamplePoints));
  RansacSample sample;
  std::vector<double> depths;
  for (int i : live) {
    if (!cloud.normals[i].isZero()) sample.with_normal.push_back(i);
    depths.push_back(cloud.points[i].z());
  }
  sample.points = std::move(live);
  if (depths.empty()) return sample;
  const size_t quarter = depths.size() / 4;
  std::nth_element(depths.begin(), depths.begin() + quarter, depths.end());
  sample.threshold_m = PlaneThreshold(options, depths[quarter]);
  return sample;
}

bool IsSampleInlier(const DepthCloud& cloud, int i, const Plane& plane, double threshold_m) {
  static const double min_cos = std::cos(kNormalToleranceDeg * kDegToRad);
  return std::abs(plane.SignedDistance(cloud.points[i])) <= threshold_m &&
         std::abs(cloud.normals[i].dot(plane.normal)) >= min_cos;
}

// Our RANSAC: each hypothesis is one point and its local normal (ComputeNormals), so that one
// good draw suffices: log(1 - confidence) / log(1 - w) draws for an inlier share w (16 at
// w = 0.35), against about 150 for three-point samples. Inliers are counted as everywhere else
// here (the distance and the normal), which needs no acos per point as PCL's normal-plane model
// does; the hypothesis with the most wins, the first on ties.
std::optional<Plane> PointNormalRansac(const DepthCloud& cloud, const RansacSample& sample,
                                       std::mt19937_64* rng) {
  if (sample.with_normal.empty()) return std::nullopt;
  std::uniform_int_distribution<size_t> pick(0, sample.with_normal.size() - 1);
  std::optional<Plane> best;
  size_t best_count = 0;
  int needed = kRansacMaxIterations;
  for (int iteration = 0; iteration < needed; ++iteration) {
    const int seed = sample.with_normal[pick(*rng)];
    const Plane plane{cloud.normals[seed], -cloud.normals[seed].dot(cloud.points[seed])};
    size_t count = 0;
    for (int i : sample.points) count += IsSampleInlier(cloud, i, plane, sample.threshold_m);
    if (count <= best_count) continue;
    best = plane;
    best_count = count;
    const double share = static_cast<double>(count) / sample.points.size();
    if (share >= 1.0) break;
    needed = std::min(
        kRansacMaxIterations,
        static_cast<int>(std::ceil(std::log(1.0 - kRansacConfidence) / std::log(1.0 - share))));
  }
  return best;
}

// ---------------------------------------------------------------------------------------------
// Sequential plane extraction (Fig. 7 (c)).

std::vector<int> LiveIndices(const std::vector<char>& live) {
  std::vector<int> indices;
  for (size_t i = 0; i < live.size(); ++i)
    if (live[i]) indices.push_back(static_cast<int>(i));
  return indices;
}

// The largest connected set of live inliers of a RANSAC plane. RANSAC's plane leans towards
// neighbouring surfaces to catch more inliers in its wide band; least squares on the connected
// inliers and a new selection pull it back.
std::vector<int> ConnectedInliers(const DepthCloud& cloud, const std::vector<int>& live_indices,
                                  const Plane& ransac_plane, const DepthFeatureOptions& options) {
  std::vector<int> inliers, component;
  Plane current = ransac_plane;
  for (int refine = 0; refine < 3; ++refine) {
    inliers.clear();
    for (int i : live_indices)
      if (IsInlier(cloud, i, current, options)) inliers.push_back(i);
    component = LargestComponent(cloud, inliers);
    if (static_cast<int>(component.size()) < options.min_inliers_per_face) break;
    const auto refit = FitPatchPlane(cloud, component, options);
    if (!refit) break;
    current = *refit;
  }
  return component;
}

// Noise tails of a surface (returns just beyond the threshold, scattered inside it) would feed
// spurious planes later: drops live points within 3 thresholds of the patch that are surrounded
// by it (5 of 8 neighbours; the edge of a neighbouring face has at most 3).
void DropNoiseTails(const DepthCloud& cloud, const PlanePatch& patch,
                    const DepthFeatureOptions& options, std::vector<char>* live) {
  std::vector<char> in_patch(cloud.point_of_cell.size(), 0);
  for (int i : patch.inliers) in_patch[cloud.cell[i]] = 1;
  for (size_t j = 0; j < live->size(); ++j) {
    if (!(*live)[j] || std::abs(patch.plane.SignedDistance(cloud.points[j])) >
                           3.0 * PlaneThreshold(options, cloud.points[j].z()))
      continue;
    int surrounding = 0;
    ForEachCellAround(cloud, cloud.cell[j], [&](int n) { surrounding += in_patch[n]; });
    if (surrounding >= 5) (*live)[j] = 0;
  }
}

// Coplanar pieces (the base on both sides of the tent) become one patch when their joint fit is
// about as good as each alone.
void MergeCoplanar(const DepthCloud& cloud, const DepthFeatureOptions& options,
                   std::vector<PlanePatch>* patches) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < patches->size() && !merged; ++a)
      for (size_t b = a + 1; b < patches->size() && !merged; ++b) {
        PlanePatch& pa = (*patches)[a];
        const PlanePatch& pb = (*patches)[b];
        if (pa.plane.normal.dot(pb.plane.normal) < std::cos(3.0 * kDegToRad)) continue;
        std::vector<int> both = pa.inliers;
        both.insert(both.end(), pb.inliers.begin(), pb.inliers.end());
        auto joint = FitPatch(cloud, both, options);
        if (!joint || joint->rms_m > 1.5 * std::max(pa.rms_m, pb.rms_m)) continue;
        pa = std::move(*joint);
        patches->erase(patches->begin() + b);
        merged = true;
      }
  }
}

}  // namespace

// Sequential RANSAC: each plane keeps its largest connected set of inliers (a plane's inliers
// elsewhere, e.g. a band of a wall along its intersection, stay for later planes), until three
// planes look like the target. Coplanar pieces are merged afterwards.
std::vector<PlanePatch> ExtractPlanes(
    const DepthCloud& cloud, const DepthFeatureOptions& options,
    const std::function<bool(const std::vector<PlanePatch>&)>& target_found) {
  std::vector<PlanePatch> patches;
  std::vector<char> live(cloud.points.size(), 1);
  std::mt19937_64 rng(options.seed);
  const PlaneSearch pcl_search = options.plane_search == DepthPlaneSearch::kPclSacNormalPlane
                                     ? MakePclPlaneSearch(cloud)
                                     : PlaneSearch{};
  // Stop after a few RANSAC planes in a row that hold no surface: what is left is edges and
  // speckle.
  int failures_in_a_row = 0;
  for (int attempt = 0; attempt < 3 * options.max_planes && failures_in_a_row < 3 &&
                        static_cast<int>(patches.size()) < options.max_planes;
       ++attempt) {
    const std::vector<int> live_indices = LiveIndices(live);
    if (static_cast<int>(live_indices.size()) < options.min_inliers_per_face) break;
    const RansacSample sample = DrawSample(cloud, live_indices, &rng, options);
    const std::optional<Plane> plane =
        pcl_search ? pcl_search(sample) : PointNormalRansac(cloud, sample, &rng);
    if (!plane) break;
    std::vector<int> ransac_inliers;
    for (int i : sample.points)
      if (IsSampleInlier(cloud, i, *plane, sample.threshold_m)) ransac_inliers.push_back(i);
    const std::vector<int> component = ConnectedInliers(cloud, live_indices, *plane, options);
    std::optional<PlanePatch> patch;
    if (static_cast<int>(component.size()) >= options.min_inliers_per_face)
      patch = FitPatch(cloud, component, options);
    if (!patch) {  // a small or degenerate surface, or edge points: do not draw them again
      for (int i : component) live[i] = 0;
      for (int i : ransac_inliers) live[i] = 0;
      ++failures_in_a_row;
      continue;
    }
    failures_in_a_row = 0;
    for (int i : component) live[i] = 0;
    DropNoiseTails(cloud, *patch, options, &live);
    patches.push_back(std::move(*patch));
    if (target_found(patches)) break;  // the rest is clutter
  }
  MergeCoplanar(cloud, options, &patches);
  return patches;
}

}  // namespace calibench::depth
