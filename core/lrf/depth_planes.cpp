// The three-face target's faces and their intersection lines in the depth image
// (papers/lrf-depth-camera-vboard.txt Section 3.1 Eq. (6)–(7), Section 4.2 step 3, Fig. 7 (c)–(d)):
// the target's three planes chosen among those the plane search found (depth_plane_search.cpp),
// separated, refitted, and intersected.
#include "core/lrf/depth_planes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/lrf/depth_cloud.h"

namespace calibench {

namespace {

using depth::DepthCloud;
using depth::IsInlier;
using depth::PlanePatch;
using depth::PlaneThreshold;

// ---------------------------------------------------------------------------------------------
// Choosing the target's three faces among the planes (Fig. 7 (c)).

double AngleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * kRadToDeg;
}

// The point where the three planes meet (A on the target); nullopt when dependent.
std::optional<Vec3> MeetingPoint(const Plane& a, const Plane& b, const Plane& c) {
  Mat3 normals;
  normals << a.normal.transpose(), b.normal.transpose(), c.normal.transpose();
  if (std::abs(normals.determinant()) < 1e-6) return std::nullopt;
  return Vec3(normals.inverse() * Vec3(-a.distance, -b.distance, -c.distance));
}

// 98th percentile of the distances from `point` to a patch's points.
double FarExtent(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  std::vector<double> d;
  for (int i : patch.inliers) d.push_back((cloud.points[i] - point).norm());
  const size_t k = std::min(d.size() - 1, static_cast<size_t>(0.98 * d.size()));
  std::nth_element(d.begin(), d.begin() + k, d.end());
  return d[k];
}

double NearestDistance(const DepthCloud& cloud, const PlanePatch& patch, const Vec3& point) {
  double best = std::numeric_limits<double>::infinity();
  for (int i : patch.inliers) best = std::min(best, (cloud.points[i] - point).norm());
  return best;
}

double MeanU(const DepthCloud& cloud, const PlanePatch& patch) {
  double sum = 0.0;
  for (int i : patch.inliers) sum += cloud.pixel_u[i];
  return sum / patch.inliers.size();
}

// Fig. 7 (c): the (base, ABC, ACD) triple whose normals make the target's angles, whose planes
// meet at a point A next to all three patches, no larger than the target, ABC left of ACD in the
// image. Walls and floor fail the angles or the size. Returns patch indices or nullopt.
std::optional<std::array<int, 3>> ChooseTriple(const DepthCloud& cloud,
                                               const std::vector<PlanePatch>& patches,
                                               const ThreeFaceTarget& target) {
  const std::array<Plane, 3> faces = target.FacePlanes();  // normals towards +z
  const std::array<double, 3> expected = {AngleDeg(faces[0].normal, faces[1].normal),
                                          AngleDeg(faces[1].normal, faces[2].normal),
                                          AngleDeg(faces[2].normal, faces[0].normal)};
  const double face_reach =
      1.15 * std::max((target.A() - target.B()).norm(), (target.A() - target.C()).norm()) + 0.05;
  double base_reach = 0.0;
  for (double sx : {-0.5, 0.5})
    for (double sy : {-0.5, 0.5})
      base_reach =
          std::max(base_reach,
                   (Vec3(sx * target.base_width, sy * target.base_height, 0) - target.A()).norm());
  base_reach = 1.15 * base_reach + 0.05;
  const double near_a = 0.3 * face_reach + 0.05;
  constexpr double kAngleTolerance = 12.0;  // degrees, per pair
  std::optional<std::array<int, 3>> best;
  double best_score = 0.0;
  const int count = static_cast<int>(patches.size());
  for (int b = 0; b < count; ++b)
    for (int f1 = 0; f1 < count; ++f1)
      for (int f2 = 0; f2 < count; ++f2) {
        if (b == f1 || b == f2 || f1 == f2) continue;
        const std::array<const PlanePatch*, 3> p = {&patches[b], &patches[f1], &patches[f2]};
        double score = 0.0;
        bool angles_match = true;
        for (int k = 0; k < 3 && angles_match; ++k) {
          const double error =
              std::abs(AngleDeg(p[k]->plane.normal, p[(k + 1) % 3]->plane.normal) - expected[k]);
          angles_match = error <= kAngleTolerance;
          score += error;
        }
        if (!angles_match || (best && score >= best_score)) continue;
        if (MeanU(cloud, *p[1]) >= MeanU(cloud, *p[2])) continue;  // ABC on the left
        const auto a = MeetingPoint(p[0]->plane, p[1]->plane, p[2]->plane);
        if (!a) continue;
        bool fits = true;
        for (int k = 0; k < 3 && fits; ++k)
          fits = NearestDistance(cloud, *p[k], *a) <= near_a &&
                 FarExtent(cloud, *p[k], *a) <= (k == 0 ? base_reach : face_reach);
        if (!fits) continue;
        best = std::array<int, 3>{b, f1, f2};
        best_score = score;
      }
  return best;
}

// Each point of the three patches goes to the one plane it is an inlier of (distance and local
// normal); points that fit two (along the edges AB, AC, AD) are left out, since they would pull
// the planes towards each other. Then the planes are fitted again.
bool ReassignAndRefit(const DepthCloud& cloud, const DepthFeatureOptions& options,
                      std::array<PlanePatch, 3>* faces) {
  std::vector<int> pool;
  for (const PlanePatch& f : *faces) pool.insert(pool.end(), f.inliers.begin(), f.inliers.end());
  std::array<std::vector<int>, 3> assigned;
  for (int i : pool) {
    int owner = -1, owners = 0;
    for (int k = 0; k < 3; ++k)
      if (IsInlier(cloud, i, (*faces)[k].plane, options)) owner = k, ++owners;
    if (owners != 1) continue;
    // A window straddling an edge can give a normal close to the dominant face's: the distance
    // to the other planes (half a threshold, ~1.5σ) catches those points.
    bool near_other = false;
    for (int k = 0; k < 3; ++k)
      near_other |= k != owner && std::abs((*faces)[k].plane.SignedDistance(cloud.points[i])) <=
                                      0.5 * PlaneThreshold(options, cloud.points[i].z());
    if (!near_other) assigned[owner].push_back(i);
  }
  std::array<PlanePatch, 3> refit;
  for (int k = 0; k < 3; ++k) {
    if (static_cast<int>(assigned[k].size()) < options.min_inliers_per_face) return false;
    auto fit = depth::FitPatch(cloud, assigned[k], options);
    if (!fit) return false;
    refit[k] = std::move(*fit);
  }
  *faces = std::move(refit);
  return true;
}

// ---------------------------------------------------------------------------------------------
// The three faces and their lines (Eq. (6)–(7)).

// Why the depth image cannot be used (intrinsics, size), in words; empty when it can.
std::string DepthImageProblem(const DepthImage& depth) {
  const DepthIntrinsics& k = depth.intrinsics;
  if (k.width <= 0 || k.height <= 0 || !(k.fx > 0) || !(k.fy > 0))
    return "depth image has no valid intrinsics (size " + std::to_string(k.width) + "x" +
           std::to_string(k.height) + ", fx and fy must be > 0)";
  if (depth.depth_m.size() != static_cast<size_t>(k.width) * k.height)
    return "depth image holds " + std::to_string(depth.depth_m.size()) + " values, expected " +
           std::to_string(k.width) + "x" + std::to_string(k.height);
  return "";
}

// The user's region clamped to the image, or the whole image.
DepthRegion ClampedRegion(const DepthIntrinsics& k, const DepthRegion* region) {
  if (!region) return DepthRegion{0, 0, k.width, k.height};
  return DepthRegion{std::clamp(region->u0, 0, k.width), std::clamp(region->v0, 0, k.height),
                     std::clamp(region->u1, 0, k.width), std::clamp(region->v1, 0, k.height)};
}

// Fig. 7 (c)–(d): segment planes, pick the target's three (base, ABC, ACD), then separate them
// and refit twice. nullopt with *reason when fewer than three faces are found.
std::optional<std::array<PlanePatch, 3>> FindFaces(const DepthCloud& cloud,
                                                   const ThreeFaceTarget& target,
                                                   const DepthFeatureOptions& options,
                                                   std::string* reason) {
  const std::vector<PlanePatch> patches =
      depth::ExtractPlanes(cloud, options, [&](const std::vector<PlanePatch>& found) {
        return ChooseTriple(cloud, found, target).has_value();
      });
  const auto triple = ChooseTriple(cloud, patches, target);
  if (!triple) {
    *reason = "fewer than three faces found: " + std::to_string(patches.size()) +
              " planes with >= " + std::to_string(options.min_inliers_per_face) +
              " connected points, no three of them with the target's face angles, size and layout";
    return std::nullopt;
  }
  std::array<PlanePatch, 3> faces = {patches[(*triple)[0]], patches[(*triple)[1]],
                                     patches[(*triple)[2]]};
  for (int iteration = 0; iteration < 2; ++iteration) {
    if (!ReassignAndRefit(cloud, options, &faces)) {
      *reason = "fewer than three faces found: after separating the faces one has fewer than " +
                std::to_string(options.min_inliers_per_face) + " points";
      return std::nullopt;
    }
  }
  return faces;
}

// Sets out->min_face_angle_deg; false with a reason when two faces are within
// min_face_angle_deg of parallel (their intersection line would be ill-conditioned).
bool CheckFaceAngles(const std::array<PlanePatch, 3>& faces, const DepthFeatureOptions& options,
                     DepthFeatures* out) {
  out->min_face_angle_deg = 90.0;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const double angle = UnsignedAngleDeg(faces[a].plane.normal, faces[b].plane.normal);
    out->min_face_angle_deg = std::min(out->min_face_angle_deg, angle);
    if (angle < options.min_face_angle_deg) {
      out->reason = NearParallelReason(FaceName(a), FaceName(b), options.min_face_angle_deg, angle);
      return false;
    }
  }
  return true;
}

// The planes (Eq. (6)) with their covariances, inlier counts and RMS, and the lines of Eq. (7):
// AB = base ∩ ABC, AC = ABC ∩ ACD, AD = ACD ∩ base; each through A, where the three planes meet,
// pointing from A into the face it borders (towards B, C, D).
bool SetPlanesAndLines(const DepthCloud& cloud, const std::array<PlanePatch, 3>& faces,
                       DepthFeatures* out) {
  const auto apex = MeetingPoint(faces[0].plane, faces[1].plane, faces[2].plane);
  if (!apex) {
    out->reason = "the three faces do not meet in a point";
    return false;
  }
  auto centroid = [&](std::initializer_list<int> which) {
    Vec3 sum = Vec3::Zero();
    double n = 0;
    for (int f : which)
      for (int i : faces[f].inliers) sum += cloud.points[i], n += 1;
    return Vec3(sum / n);
  };
  const std::array<Vec3, 3> towards = {centroid({1}), centroid({1, 2}), centroid({2})};
  double sum_sq = 0.0;
  size_t total = 0;
  for (int f = 0; f < 3; ++f) {
    out->planes[f] = faces[f].plane;
    out->plane_covariances[f] = faces[f].covariance;
    out->inlier_counts[f] = static_cast<int>(faces[f].inliers.size());
    auto line = IntersectPlanes(faces[f].plane, faces[(f + 1) % 3].plane);
    if (!line) {
      out->reason = std::string(FaceName(f)) + " and " + FaceName((f + 1) % 3) + " are parallel";
      return false;
    }
    line->point = line->point + line->direction.dot(*apex - line->point) * line->direction;
    if (line->direction.dot(towards[f] - *apex) < 0) line->direction = -line->direction;
    out->lines[f] = *line;
    sum_sq += faces[f].rms_m * faces[f].rms_m * faces[f].inliers.size();
    total += faces[f].inliers.size();
  }
  out->rms_m = std::sqrt(sum_sq / total);
  return true;
}

// Per depth pixel: the face whose inlier's stride × stride block covers it, -1 elsewhere.
std::vector<signed char> FaceOfPixel(const DepthCloud& cloud,
                                     const std::array<PlanePatch, 3>& faces,
                                     const DepthIntrinsics& k, int stride) {
  std::vector<signed char> face_of_pixel(static_cast<size_t>(k.width) * k.height, -1);
  for (int f = 0; f < 3; ++f)
    for (int i : faces[f].inliers)
      for (int v = cloud.pixel_v[i]; v < std::min(k.height, cloud.pixel_v[i] + stride); ++v)
        for (int u = cloud.pixel_u[i]; u < std::min(k.width, cloud.pixel_u[i] + stride); ++u)
          face_of_pixel[static_cast<size_t>(v) * k.width + u] = static_cast<signed char>(f);
  return face_of_pixel;
}

}  // namespace

bool DepthFeatureOptions::Check(std::string* why) const {
  if (stride_px < 1) return FailCheck(why, "stride_px must be >= 1");
  if (!(max_depth_m > 0)) return FailCheck(why, "max_depth_m must be > 0 (metres)");
  if (!(plane_threshold_m > 0)) return FailCheck(why, "plane_threshold_m must be > 0 (metres)");
  if (!(plane_threshold_per_m2 >= 0))
    return FailCheck(why, "plane_threshold_per_m2 must be >= 0 (1/m)");
  if (min_inliers_per_face < 4) return FailCheck(why, "min_inliers_per_face must be >= 4");
  if (max_planes < 3) return FailCheck(why, "max_planes must be >= 3 (the target has three faces)");
  if (!(min_face_angle_deg >= 0 && min_face_angle_deg < 90))
    return FailCheck(why, "min_face_angle_deg must be in [0, 90)");
  return true;
}

DepthFeatures ExtractDepthFeatures(const DepthImage& depth, const ThreeFaceTarget& target,
                                   const DepthFeatureOptions& options, const DepthRegion* region) {
  DepthFeatures out;
  out.reason = InputProblem(options, "depth feature options", target);
  if (out.reason.empty()) out.reason = DepthImageProblem(depth);
  if (!out.reason.empty()) return out;
  const DepthIntrinsics& k = depth.intrinsics;
  DepthCloud cloud =
      depth::BackProject(depth, ClampedRegion(k, region), options.stride_px, options.max_depth_m);
  if (cloud.points.empty()) {
    out.reason =
        region ? "no depth data inside the selected region" : "no depth data (all pixels 0)";
    return out;
  }
  depth::ComputeNormals(k, options, &cloud);
  const std::optional<std::array<PlanePatch, 3>> faces =
      FindFaces(cloud, target, options, &out.reason);
  if (!faces) return out;
  if (!CheckFaceAngles(*faces, options, &out)) return out;
  if (!SetPlanesAndLines(cloud, *faces, &out)) return out;
  out.face_of_pixel = FaceOfPixel(cloud, *faces, k, options.stride_px);
  out.ok = true;
  return out;
}

std::optional<Line3> IntersectPlanes(const Plane& a, const Plane& b) {
  const Vec3 direction = a.normal.cross(b.normal);
  const double sq = direction.squaredNorm();
  if (direction.norm() < 1e-6) return std::nullopt;
  // The point of the line closest to the origin: p·n_a = -d_a, p·n_b = -d_b, p·dir = 0.
  Line3 line;
  line.point =
      (-a.distance * b.normal.cross(direction) - b.distance * direction.cross(a.normal)) / sq;
  line.direction = direction.normalized();
  return line;
}

}  // namespace calibench
