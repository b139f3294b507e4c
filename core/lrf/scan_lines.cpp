// Lines in the 2D laser scan (papers/lrf-depth-camera-vboard.txt Section 3.1, Section 4.2 step 1,
// Fig. 4 and 6): the three-face target's polyline E-F-G-H-I, its face lines and corners.
#include "core/lrf/scan_lines.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/base/text.h"

namespace calibench {

namespace {

// The scan lines EI (base), FG (ABC), GH (ACD) in reasons.
const char* const kLineNames[3] = {"EI", "FG", "GH"};

struct Segment {
  std::vector<Vec2> points;  // raw returns
  std::vector<int> polyline_positions;
  Line2 line;
  double length = 0.0;  // between the projections of its end returns, metres
};

Segment MakeSegment(const ScanPolyline& polyline, int first, int last) {
  Segment segment;
  for (int k = first; k <= last; ++k) {
    segment.points.push_back(polyline[k].point);
    segment.polyline_positions.push_back(k);
  }
  if (segment.points.size() >= 2) {
    segment.line = FitLine2(segment.points);
    segment.length = (segment.points.back() - segment.points.front()).norm();
  }
  return segment;
}

// The polyline's straight runs long enough to be a face. Short pieces are the rounded corners of
// the smoothing or mixed returns, not faces.
std::vector<Segment> StraightSegments(const ScanPolyline& polyline,
                                      const ScanFeatureOptions& options) {
  std::vector<Segment> segments;
  for (const auto& [first, last] : StraightRuns(polyline, options.line_threshold_m)) {
    Segment segment = MakeSegment(polyline, first, last);
    if (static_cast<int>(segment.points.size()) >= std::max(3, options.min_points_per_face / 2) &&
        segment.length >= 0.5 * options.min_face_length_m)
      segments.push_back(std::move(segment));
  }
  return segments;
}

// The returns of the outer segments together: both lie on the base (paper Fig. 4, line EI).
std::vector<Vec2> BasePoints(const Segment& first, const Segment& last) {
  std::vector<Vec2> points = first.points;
  points.insert(points.end(), last.points.begin(), last.points.end());
  return points;
}

// Target lengths bounding what a scan can see of it (a plane section of a triangle is at most
// its longest side).
struct TargetSpans {
  double max_face_chord = 0.0;  // longest side of ABC / ACD
  double max_footprint = 0.0;   // longest side of ABD (F–H)
  double max_bump = 0.0;        // ridge height
};

TargetSpans SpansOf(const ThreeFaceTarget& t) {
  TargetSpans spans;
  spans.max_face_chord =
      std::max({(t.A() - t.B()).norm(), (t.A() - t.C()).norm(), (t.B() - t.C()).norm(),
                (t.A() - t.D()).norm(), (t.C() - t.D()).norm()});
  spans.max_footprint =
      std::max({(t.A() - t.B()).norm(), (t.B() - t.D()).norm(), (t.A() - t.D()).norm()});
  spans.max_bump = t.ridge_height;
  return spans;
}

// Does base–face–face–base (segments s[0..3] in scan order) look like the target? Returns a
// score (smaller is better) or nullopt with *why.
std::optional<double> MatchWindow(const std::array<const Segment*, 4>& s, const TargetSpans& spans,
                                  const ScanFeatureOptions& options, std::string* why) {
  for (int k = 0; k < 4; ++k) {
    if (static_cast<int>(s[k]->points.size()) < options.min_points_per_face ||
        s[k]->length < options.min_face_length_m) {
      *why = "segment " + std::to_string(k + 1) + " of 4 is too short (" +
             std::to_string(s[k]->points.size()) + " returns, " + Printf("%.3f m)", s[k]->length);
      return std::nullopt;
    }
  }
  const double chord_limit = 1.2 * spans.max_face_chord + 0.05;
  if (s[1]->length > chord_limit || s[2]->length > chord_limit) {
    *why = "the middle segments are longer than the target's faces (" +
           Printf("%.2f m", std::max(s[1]->length, s[2]->length)) +
           Printf(" > %.2f m)", chord_limit);
    return std::nullopt;
  }
  const std::vector<Vec2> base_points = BasePoints(*s[0], *s[3]);
  const Line2 base = FitLine2(base_points);  // normal towards the sensor (offset >= 0)
  const double base_rms = LineRms(base, base_points);
  if (base_rms > options.line_threshold_m) {
    *why = "the outer segments are not collinear (" + Printf("RMS %.3f m)", base_rms);
    return std::nullopt;
  }
  // The two middle segments form a bump towards the sensor, at most the ridge height high.
  const auto ridge = IntersectLines(s[1]->line, s[2]->line);
  const auto foot_a = IntersectLines(s[1]->line, base);
  const auto foot_b = IntersectLines(s[2]->line, base);
  if (!ridge || !foot_a || !foot_b) {
    *why = "the middle segments are parallel to each other or to the base";
    return std::nullopt;
  }
  const double bump = base.SignedDistance(*ridge);
  if (bump < std::max(options.line_threshold_m, 0.01) || bump > 1.3 * spans.max_bump + 0.05) {
    *why = "the middle segments do not form the tent's ridge towards the sensor (height " +
           Printf("%.3f m)", bump);
    return std::nullopt;
  }
  const double footprint = (*foot_a - *foot_b).norm();
  if (footprint > 1.2 * spans.max_footprint + 0.05) {
    *why = "the tent's footprint on the scan is too wide (" + Printf("%.2f m)", footprint);
    return std::nullopt;
  }
  return base_rms / options.line_threshold_m;
}

struct Window {
  const ScanPolyline* polyline = nullptr;
  std::array<Segment, 4> segments;
  double score = 0.0;
};

// Fig. 6 (c): the polyline E-F-G-H-I is four straight segments in a row. The best-scoring such
// window over all polylines; nullopt with *reason (the first rejection's) when none matches.
std::optional<Window> FindTargetWindow(const std::vector<ScanPolyline>& polylines,
                                       const TargetSpans& spans, const ScanFeatureOptions& options,
                                       std::string* reason) {
  std::optional<Window> best;
  size_t most_segments = 0;
  std::string first_rejection;
  for (const ScanPolyline& polyline : polylines) {
    const std::vector<Segment> segments = StraightSegments(polyline, options);
    most_segments = std::max(most_segments, segments.size());
    for (size_t i = 0; i + 3 < segments.size(); ++i) {
      std::array<const Segment*, 4> window = {&segments[i], &segments[i + 1], &segments[i + 2],
                                              &segments[i + 3]};
      std::string rejection;
      const auto score = MatchWindow(window, spans, options, &rejection);
      if (!score) {
        if (first_rejection.empty()) first_rejection = rejection;
        continue;
      }
      if (!best || *score < best->score)
        best = Window{
            &polyline, {segments[i], segments[i + 1], segments[i + 2], segments[i + 3]}, *score};
    }
  }
  if (!best && most_segments < 4) {
    *reason = "target crosses fewer than three faces (found " + std::to_string(most_segments) +
              " straight segments in a row, need base, two faces, base)";
  } else if (!best) {
    *reason = "no four straight segments in a row match the target: " + first_rejection;
  }
  return best;
}

// The window's returns from E to I.
ScanPolyline WindowSpan(const Window& w) {
  const int first = w.segments[0].polyline_positions.front();
  const int last = w.segments[3].polyline_positions.back();
  return ScanPolyline(w.polyline->begin() + first, w.polyline->begin() + last + 1);
}

// The lines EI (both outer segments), FG and GH of the window. Faces as seen from the sensor:
// ABC on the left (larger scan angle, LRF y is left).
std::array<Line2, 3> WindowLines(const Window& w, bool angle_increasing) {
  const Segment& abc = angle_increasing ? w.segments[2] : w.segments[1];
  const Segment& acd = angle_increasing ? w.segments[1] : w.segments[2];
  return {FitLine2(BasePoints(w.segments[0], w.segments[3])), abc.line, acd.line};
}

// ---------------------------------------------------------------------------------------------
// Face lines and corners (paper Section 3.1: EI, FG, GH by RANSAC, then F, G, H).

// Polar angle of a point, unwrapped to the scan's angle near `reference` (radians).
double AngleNear(const Vec2& p, double reference) {
  double a = std::atan2(p.y(), p.x());
  while (a - reference > M_PI) a -= 2 * M_PI;
  while (a - reference < -M_PI) a += 2 * M_PI;
  return a;
}

// The returns of `span` per face (0 base, 1 ABC, 2 ACD), assigned by their scan angle between
// the corners F, G, H of `lines`; returns within max(2 rays, 5 mm across the ray) of a corner are
// left out (mixed returns and beam footprint live there). nullopt with *reason when two lines are
// parallel.
std::optional<std::array<std::vector<Vec2>, 3>> PointsBetweenCorners(
    const LaserScan& scan, const ScanPolyline& span, const std::array<Line2, 3>& lines,
    std::string* reason) {
  const std::array<std::optional<Vec2>, 3> corners = {IntersectLines(lines[0], lines[1]),
                                                      IntersectLines(lines[1], lines[2]),
                                                      IntersectLines(lines[2], lines[0])};
  for (int k = 0; k < 3; ++k) {
    if (corners[k]) continue;
    *reason =
        std::string("lines ") + kLineNames[k] + " and " + kLineNames[(k + 1) % 3] + " are parallel";
    return std::nullopt;
  }
  const double reference = std::atan2(corners[1]->y(), corners[1]->x());
  const double a_f = AngleNear(*corners[0], reference);
  const double a_g = AngleNear(*corners[1], reference);
  const double a_h = AngleNear(*corners[2], reference);
  std::array<std::vector<Vec2>, 3> face_points;
  for (const ScanPoint& p : span) {
    const double a = AngleNear(p.point, reference);
    const double margin = std::max(2.0 * std::abs(scan.angle_increment), 0.005 / p.range);
    if (std::abs(a - a_f) < margin || std::abs(a - a_g) < margin || std::abs(a - a_h) < margin)
      continue;
    int face = 0;
    if ((a - a_f) * (a - a_g) < 0)
      face = 1;  // between F and G: ABC
    else if ((a - a_g) * (a - a_h) < 0)
      face = 2;
    face_points[face].push_back(p.point);
  }
  return face_points;
}

// Given the lines (0 base, 1 ABC, 2 ACD) fits the faces again from the returns of the window's
// span, each assigned to its face between the corners (PointsBetweenCorners).
bool FitFaces(const LaserScan& scan, const ScanPolyline& span, const ScanFeatureOptions& options,
              ScanFeatures* out) {
  // Two passes: the corners from the segments' lines, then from the refined lines. More passes
  // can drift on a face seen at grazing incidence (few returns, a poorly known direction).
  for (int iteration = 0; iteration < 2; ++iteration) {
    const auto face_points = PointsBetweenCorners(scan, span, out->lines, &out->reason);
    if (!face_points) return false;
    for (int k = 0; k < 3; ++k) {
      if (static_cast<int>((*face_points)[k].size()) >= options.min_points_per_face) continue;
      if (iteration > 0) return true;  // keep the first pass
      out->reason = std::string(FaceName(k)) + " has only " +
                    std::to_string((*face_points)[k].size()) +
                    " returns away from the corners (need " +
                    std::to_string(options.min_points_per_face) + ")";
      return false;
    }
    for (int k = 0; k < 3; ++k) {
      std::vector<int> inliers;
      out->lines[k] = RobustFitLine((*face_points)[k], options.line_threshold_m,
                                    options.ransac_iterations, &inliers);
      out->face_points[k].clear();
      for (int i : inliers) out->face_points[k].push_back((*face_points)[k][i]);
    }
  }
  return true;
}

// The corners F = EI ∩ FG, G = FG ∩ GH, H = GH ∩ EI (paper Section 3.1), refusing lines within
// min_line_angle_deg of parallel.
bool IntersectFaceLines(const ScanFeatureOptions& options, ScanFeatures* out) {
  for (int k = 0; k < 3; ++k) {
    const int next = (k + 1) % 3;
    const double angle = UnsignedAngleDeg(out->lines[k].normal, out->lines[next].normal);
    if (angle < options.min_line_angle_deg) {
      out->reason = NearParallelReason(std::string("lines ") + kLineNames[k], kLineNames[next],
                                       options.min_line_angle_deg, angle);
      return false;
    }
    out->corners[k] = *IntersectLines(out->lines[k], out->lines[next]);
  }
  return true;
}

// RMS point-to-line distance over the face points of all three faces.
double FaceLinesRms(const ScanFeatures& features) {
  double sum_sq = 0.0;
  size_t count = 0;
  for (int k = 0; k < 3; ++k)
    for (const Vec2& p : features.face_points[k]) {
      sum_sq += std::pow(features.lines[k].SignedDistance(p), 2);
      ++count;
    }
  return std::sqrt(sum_sq / std::max<size_t>(1, count));
}

}  // namespace

bool ScanFeatureOptions::Check(std::string* why) const {
  if (!(break_distance_m > 0)) return FailCheck(why, "break_distance_m must be > 0 (metres)");
  if (!(break_angle_factor >= 0)) return FailCheck(why, "break_angle_factor must be >= 0");
  if (!(line_threshold_m > 0)) return FailCheck(why, "line_threshold_m must be > 0 (metres)");
  if (min_points_per_face < 2) return FailCheck(why, "min_points_per_face must be >= 2");
  if (!(min_face_length_m >= 0)) return FailCheck(why, "min_face_length_m must be >= 0 (metres)");
  if (!(min_line_angle_deg >= 0 && min_line_angle_deg < 90))
    return FailCheck(why, "min_line_angle_deg must be in [0, 90)");
  if (ransac_iterations < 1) return FailCheck(why, "ransac_iterations must be >= 1");
  return true;
}

ScanFeatures ExtractScanFeatures(const LaserScan& scan, const ThreeFaceTarget& target,
                                 const ScanFeatureOptions& options, const ScanRegion* region) {
  ScanFeatures out;
  out.reason = InputProblem(options, "scan feature options", target);
  if (!out.reason.empty()) return out;
  const std::vector<ScanPolyline> polylines = ScanPolylines(
      scan, region, options.break_distance_m, options.break_angle_factor, &out.reason);
  if (polylines.empty()) return out;
  const std::optional<Window> window =
      FindTargetWindow(polylines, SpansOf(target), options, &out.reason);
  if (!window) return out;
  const ScanPolyline span = WindowSpan(*window);
  out.lines = WindowLines(*window, scan.angle_increment > 0);
  if (!FitFaces(scan, span, options, &out)) return out;
  if (!IntersectFaceLines(options, &out)) return out;
  out.rms_m = FaceLinesRms(out);
  for (const ScanPoint& p : span) out.target_indices.push_back(p.index);
  out.ok = true;
  return out;
}

}  // namespace calibench
