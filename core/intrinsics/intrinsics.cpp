// CalibrateIntrinsics: OpenCV's calibrateCamera / fisheye::calibrate with reject-and-refit, the
// parameters' covariance (from the Jacobian's Schur complement; OpenCV reports σ for the pinhole
// only, and no correlations), and the stop rule in words.
#include "core/intrinsics/intrinsics.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <stdexcept>

#include "core/base/statistics.h"

namespace calibench {
namespace {

struct CvViews {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
};

CvViews ToCv(const std::vector<IntrinsicsView>& views, const std::vector<size_t>& used) {
  CvViews cv_views;
  for (const size_t i : used) {
    const BoardDetection& d = views[i].detection;
    std::vector<cv::Point3f> object;
    std::vector<cv::Point2f> image;
    for (size_t k = 0; k < d.pixels.size(); ++k) {
      object.emplace_back(static_cast<float>(d.board_points[k].x()),
                          static_cast<float>(d.board_points[k].y()), 0.0f);
      image.emplace_back(static_cast<float>(d.pixels[k].x()), static_cast<float>(d.pixels[k].y()));
    }
    cv_views.object.push_back(std::move(object));
    cv_views.image.push_back(std::move(image));
  }
  return cv_views;
}

double Rms(const std::vector<cv::Point2f>& observed, const std::vector<cv::Point2f>& projected) {
  double sum = 0.0;
  for (size_t k = 0; k < observed.size(); ++k) {
    const cv::Point2f d = observed[k] - projected[k];
    sum += d.x * d.x + d.y * d.y;
  }
  return observed.empty() ? 0.0 : std::sqrt(sum / observed.size());
}

struct Fit {
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<double> view_rms;  // per used view
  double rms = 0.0;
  Eigen::MatrixXd covariance;  // of fx fy cx cy, distortion (IntrinsicsCovariance)
  // Fisheye: views (indices into the fitted views) the refit could not start from; the caller
  // drops them and fits again.
  std::vector<size_t> beyond_start;
};

// The covariance of [fx fy cx cy distortion...] from the projection's Jacobian (OpenCV's
// projectPoints / fisheye::projectPoints): the intrinsics' block of the normal matrix with every
// view's pose eliminated (Schur complement), scaled by the residuals' variance, as calibrateCamera
// does for its σ (which it reports as standard deviations only; the correlations matter where the
// covariance is propagated into the extrinsic). A parameter held fixed (k3 with --fix-k3) has a
// zero row and column.
Eigen::MatrixXd IntrinsicsCovariance(const CvViews& v, const Fit& fit, bool fisheye, bool fix_k3) {
  const int n = fisheye ? 8 : 9;
  // Each parameter's column in OpenCV's Jacobian, and the pose's six columns.
  std::vector<int> parameter_column, parameter_index;
  for (int i = 0; i < n; ++i) {
    if (!fisheye && fix_k3 && i == 8) continue;
    parameter_index.push_back(i);
    parameter_column.push_back(fisheye ? i : 6 + i);  // pinhole: rvec tvec f c dist
  }
  const int first_pose_column = fisheye ? 8 : 0;
  const int m = static_cast<int>(parameter_index.size());
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(m, m);
  double squared = 0.0;
  int residuals = 0;
  for (size_t i = 0; i < v.object.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::Mat jacobian;
    if (fisheye)
      cv::fisheye::projectPoints(v.object[i], projected, fit.rvecs[i], fit.tvecs[i], fit.K, fit.D,
                                 0.0, jacobian);
    else
      cv::projectPoints(v.object[i], fit.rvecs[i], fit.tvecs[i], fit.K, fit.D, projected, jacobian);
    jacobian.convertTo(jacobian, CV_64F);
    Eigen::MatrixXd A(jacobian.rows, m), B(jacobian.rows, 6);
    for (int r = 0; r < jacobian.rows; ++r) {
      for (int c = 0; c < m; ++c) A(r, c) = jacobian.at<double>(r, parameter_column[c]);
      for (int c = 0; c < 6; ++c) B(r, c) = jacobian.at<double>(r, first_pose_column + c);
    }
    const Eigen::Matrix<double, 6, 6> C = B.transpose() * B;
    reduced += A.transpose() * A - (A.transpose() * B) * C.ldlt().solve(B.transpose() * A);
    for (size_t k = 0; k < projected.size(); ++k) {
      const cv::Point2f d = v.image[i][k] - projected[k];
      squared += d.x * d.x + d.y * d.y;
    }
    residuals += 2 * static_cast<int>(projected.size());
  }
  const int dof = residuals - m - 6 * static_cast<int>(v.object.size());
  const double variance = dof > 0 ? squared / dof : 0.0;
  Eigen::MatrixXd covariance = variance * reduced.inverse();
  covariance = (0.5 * (covariance + covariance.transpose())).eval();
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) full(parameter_index[a], parameter_index[b]) = covariance(a, b);
  return full;
}

Fit FitPinhole(const CvViews& v, const cv::Size& size, const IntrinsicsOptions& o) {
  Fit fit;
  cv::Mat std_intrinsics, std_extrinsics, per_view;
  const int flags = o.estimate_k3 ? 0 : cv::CALIB_FIX_K3;
  fit.rms = cv::calibrateCamera(
      v.object, v.image, size, fit.K, fit.D, fit.rvecs, fit.tvecs, std_intrinsics, std_extrinsics,
      per_view, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  for (int i = 0; i < per_view.rows; ++i) fit.view_rms.push_back(per_view.at<double>(i));
  fit.covariance = IntrinsicsCovariance(v, fit, /*fisheye=*/false, !o.estimate_k3);
  return fit;
}

// fisheye::calibrate starts from f = max(w, h) / pi and no distortion, and its first poses come
// from points undistorted with that guess: beyond ~60 deg off axis the guess maps them past the
// horizon and the homography fails ("fabs(norm_u1) > 0"). So the views whose corners all lie
// within that radius are calibrated first, and every view is refined from there.
Fit FitFisheye(const CvViews& v, const cv::Size& size) {
  auto calibrate = [&](const std::vector<size_t>& which, Fit* fit, int extra_flags) {
    std::vector<cv::Mat> object, image;  // 1xN CV_64FC3 / CV_64FC2, as fisheye::calibrate wants
    for (const size_t i : which) {
      cv::Mat o(1, static_cast<int>(v.object[i].size()), CV_64FC3);
      cv::Mat p(1, static_cast<int>(v.image[i].size()), CV_64FC2);
      for (size_t k = 0; k < v.object[i].size(); ++k) {
        o.at<cv::Vec3d>(0, static_cast<int>(k)) =
            cv::Vec3d(v.object[i][k].x, v.object[i][k].y, v.object[i][k].z);
        p.at<cv::Vec2d>(0, static_cast<int>(k)) = cv::Vec2d(v.image[i][k].x, v.image[i][k].y);
      }
      object.push_back(o);
      image.push_back(p);
    }
    fit->rvecs.clear(), fit->tvecs.clear();  // outputs, sized by this call's views
    fit->rms = cv::fisheye::calibrate(
        object, image, size, fit->K, fit->D, fit->rvecs, fit->tvecs,
        cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW | extra_flags,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12));
  };
  std::vector<size_t> all(v.object.size()), central;
  const double radius = 1.05 * std::max(size.width, size.height) / CV_PI;  // ~60 deg at the guess
  const cv::Point2f centre(0.5f * size.width, 0.5f * size.height);
  for (size_t i = 0; i < all.size(); ++i) {
    all[i] = i;
    bool inside = true;
    for (const cv::Point2f& p : v.image[i]) inside &= cv::norm(p - centre) < radius;
    if (inside) central.push_back(i);
  }
  Fit fit;
  if (central.size() >= 3 && central.size() < all.size()) {
    calibrate(central, &fit, 0);
    // The refit's first poses come from points undistorted by that camera; a view with corners
    // it cannot undistort (past ~80 deg, or its iteration diverging) would break them again.
    std::vector<size_t> usable;
    for (const size_t i : all) {
      std::vector<cv::Point2f> normalized;
      cv::fisheye::undistortPoints(v.image[i], normalized, fit.K, fit.D);
      bool finite = true;
      for (const cv::Point2f& p : normalized)
        finite &= std::isfinite(p.x) && std::isfinite(p.y) && cv::norm(p) < 5.7;  // tan 80 deg
      if (finite) usable.push_back(i);
    }
    if (usable.size() < all.size()) {
      for (const size_t i : all)
        if (!std::binary_search(usable.begin(), usable.end(), i)) fit.beyond_start.push_back(i);
      return fit;
    }
    calibrate(all, &fit, cv::fisheye::CALIB_USE_INTRINSIC_GUESS);
  } else {
    calibrate(all, &fit, 0);
  }
  for (size_t i = 0; i < v.object.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::fisheye::projectPoints(v.object[i], projected, fit.rvecs[i], fit.tvecs[i], fit.K, fit.D);
    fit.view_rms.push_back(Rms(v.image[i], projected));
  }
  // The views' RMS combined as calibrate's: over every corner.
  double squared = 0.0;
  size_t corners = 0;
  for (size_t i = 0; i < v.object.size(); ++i) {
    squared += fit.view_rms[i] * fit.view_rms[i] * v.image[i].size();
    corners += v.image[i].size();
  }
  fit.rms = std::sqrt(squared / corners);
  fit.covariance = IntrinsicsCovariance(v, fit, /*fisheye=*/true, false);
  return fit;
}

// Drops the views at positions k of `used` whose reason(k) is not empty, saying why in their
// image entries; true when any was dropped.
template <typename Reason>
bool DropViews(const Reason& reason, std::vector<size_t>* used,
               std::vector<IntrinsicsImage>* images) {
  std::vector<size_t> kept;
  for (size_t k = 0; k < used->size(); ++k) {
    const std::string why = reason(k);
    if (why.empty()) {
      kept.push_back((*used)[k]);
      continue;
    }
    (*images)[(*used)[k]].used = false;
    (*images)[(*used)[k]].reason = why;
  }
  const bool dropped = kept.size() < used->size();
  *used = std::move(kept);
  return dropped;
}

// The fitted camera, its parameters in order with their σ, and the RMS into *result.
void FillCamera(const Fit& fit, CameraModelType model, int width, int height,
                IntrinsicsResult* result) {
  const bool fisheye = model == CameraModelType::kKannalaBrandt;
  CameraModel& camera = result->camera;
  camera.type = model;
  camera.width = width, camera.height = height;
  camera.fx = fit.K.at<double>(0, 0), camera.fy = fit.K.at<double>(1, 1);
  camera.cx = fit.K.at<double>(0, 2), camera.cy = fit.K.at<double>(1, 2);
  const int coefficients = fisheye ? 4 : 5;
  for (int i = 0; i < coefficients; ++i) camera.distortion.push_back(fit.D.at<double>(i));
  result->rms_px = fit.rms;
  result->parameter_names = {"fx", "fy", "cx", "cy"};
  for (const char* name : fisheye ? std::vector<const char*>{"k1", "k2", "k3", "k4"}
                                  : std::vector<const char*>{"k1", "k2", "p1", "p2", "k3"})
    result->parameter_names.push_back(name);
  result->parameters = {camera.fx, camera.fy, camera.cx, camera.cy};
  result->parameters.insert(result->parameters.end(), camera.distortion.begin(),
                            camera.distortion.end());
  const Eigen::Index n = fit.covariance.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    result->sigmas.push_back(std::sqrt(std::max(0.0, fit.covariance(i, i))));
    for (Eigen::Index j = 0; j < n; ++j) camera.covariance.push_back(fit.covariance(i, j));
  }
}

std::string Percent(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f %%", 100.0 * value);
  return text;
}

std::string Verdict(const IntrinsicsResult& r, const IntrinsicsOptions& o, bool* good) {
  std::vector<std::string> problems;
  char text[160];
  if (r.rms_px >= o.max_rms_px) {
    std::snprintf(text, sizeof(text),
                  "RMS %.2f px is not below %.2f px (blurred images, a bent board, or the wrong "
                  "lens model?)",
                  r.rms_px, o.max_rms_px);
    problems.push_back(text);
  }
  for (int i = 0; i < 4; ++i) {
    const double relative = 1.96 * r.sigmas[i] / std::abs(r.parameters[i]);
    if (relative >= o.max_relative_ci) {
      std::snprintf(text, sizeof(text),
                    "%s is known to +-%s only (95 %%, needs < %s): more views, tilted boards",
                    r.parameter_names[i].c_str(), Percent(relative).c_str(),
                    Percent(o.max_relative_ci).c_str());
      problems.push_back(text);
    }
  }
  if (!r.coverage.missing.empty()) {
    std::string where;
    for (const std::string& m : r.coverage.missing) where += (where.empty() ? "" : ", ") + m;
    problems.push_back("no corners near the " + where +
                       ": hold the board there, where the distortion lives");
  }
  *good = problems.empty();
  if (*good) {
    double worst = 0.0;
    for (int i = 0; i < 4; ++i) worst = std::max(worst, 1.96 * r.sigmas[i] / r.parameters[i]);
    std::snprintf(text, sizeof(text),
                  "good: RMS %.2f px, focal length and principal point known to +-%s (95 %%), "
                  "corners over the whole image",
                  r.rms_px, Percent(worst).c_str());
    return text;
  }
  std::string words = "not yet: ";
  for (size_t i = 0; i < problems.size(); ++i) words += (i ? "; " : "") + problems[i];
  return words;
}

}  // namespace

bool IntrinsicsOptions::Check(std::string* why) const {
  if (model != CameraModelType::kPinholeRadTan && model != CameraModelType::kKannalaBrandt) {
    *why = "intrinsics: the model must be pinhole-radtan or kannala-brandt";
    return false;
  }
  if (!(reject_factor > 1.0 && max_rounds >= 0 && min_images >= 3 && min_corners >= 4 &&
        max_relative_ci > 0.0 && max_rms_px > 0.0 && grid_columns >= 3 && grid_rows >= 3)) {
    *why =
        "intrinsics: reject_factor > 1, max_rounds >= 0, min_images >= 3, min_corners >= 4, "
        "positive stop-rule bounds and a grid of at least 3 x 3 cells";
    return false;
  }
  return true;
}

IntrinsicsCoverage MeasureCoverage(const std::vector<IntrinsicsView>& views, int width, int height,
                                   const IntrinsicsOptions& o) {
  IntrinsicsCoverage c;
  c.columns = o.grid_columns, c.rows = o.grid_rows;
  c.counts.assign(static_cast<size_t>(c.columns * c.rows), 0);
  for (const IntrinsicsView& v : views)
    for (const Vec2& p : v.detection.pixels) {
      const int i = std::clamp(static_cast<int>(p.x() / width * c.columns), 0, c.columns - 1);
      const int j = std::clamp(static_cast<int>(p.y() / height * c.rows), 0, c.rows - 1);
      ++c.counts[static_cast<size_t>(j * c.columns + i)];
    }
  auto at = [&](int i, int j) { return c.counts[static_cast<size_t>(j * c.columns + i)]; };
  int covered = 0, border = 0, border_covered = 0;
  for (int j = 0; j < c.rows; ++j)
    for (int i = 0; i < c.columns; ++i) {
      covered += at(i, j) > 0;
      if (i == 0 || j == 0 || i == c.columns - 1 || j == c.rows - 1) {
        ++border;
        border_covered += at(i, j) > 0;
      }
    }
  c.cells_covered = static_cast<double>(covered) / c.counts.size();
  c.border_covered = static_cast<double>(border_covered) / border;
  // A border is missing when none of its inner cells (the corners aside) has a corner.
  auto empty_line = [&](bool column, int fixed) {
    const int n = column ? c.rows : c.columns;
    for (int k = 1; k < n - 1; ++k)
      if (column ? at(fixed, k) : at(k, fixed)) return false;
    return true;
  };
  const bool left = empty_line(true, 0), right = empty_line(true, c.columns - 1);
  const bool top = empty_line(false, 0), bottom = empty_line(false, c.rows - 1);
  if (left) c.missing.push_back("left border");
  if (right) c.missing.push_back("right border");
  if (top) c.missing.push_back("top border");
  if (bottom) c.missing.push_back("bottom border");
  const struct {
    int i, j;
    bool near_missing;
    const char* name;
  } corners[] = {{0, 0, left || top, "top-left corner"},
                 {c.columns - 1, 0, right || top, "top-right corner"},
                 {0, c.rows - 1, left || bottom, "bottom-left corner"},
                 {c.columns - 1, c.rows - 1, right || bottom, "bottom-right corner"}};
  for (const auto& corner : corners)
    if (!corner.near_missing && at(corner.i, corner.j) == 0) c.missing.push_back(corner.name);
  return c;
}

std::vector<Eigen::AlignedBox2d> EmptyCells(const IntrinsicsCoverage& coverage, int width,
                                            int height) {
  std::vector<Eigen::AlignedBox2d> cells;
  for (int j = 0; j < coverage.rows; ++j) {
    for (int i = 0; i < coverage.columns; ++i) {
      if (coverage.counts[static_cast<size_t>(j * coverage.columns + i)] > 0) continue;
      const double cell_w = static_cast<double>(width) / coverage.columns;
      const double cell_h = static_cast<double>(height) / coverage.rows;
      // As MeasureCoverage counts: cell i holds x in [i w / columns, (i + 1) w / columns).
      cells.emplace_back(Vec2(i * cell_w, j * cell_h), Vec2((i + 1) * cell_w, (j + 1) * cell_h));
    }
  }
  return cells;
}

IntrinsicsResult CalibrateIntrinsics(const std::vector<IntrinsicsView>& views, int width,
                                     int height, const IntrinsicsOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument(why);
  const bool fisheye = options.model == CameraModelType::kKannalaBrandt;
  IntrinsicsResult result;
  std::vector<size_t> used;
  for (size_t i = 0; i < views.size(); ++i) {
    IntrinsicsImage image;
    image.name = views[i].name;
    image.corners = static_cast<int>(views[i].detection.pixels.size());
    if (image.corners < options.min_corners) {
      image.reason = "only " + std::to_string(image.corners) + " corners";
    } else {
      used.push_back(i);
      image.used = true;
    }
    result.images.push_back(image);
  }
  const cv::Size size(width, height);
  Fit fit;
  for (int round = 0;; ++round) {
    if (static_cast<int>(used.size()) < options.min_images)
      throw std::invalid_argument("intrinsics need " + std::to_string(options.min_images) +
                                  " images with the board, " + std::to_string(used.size()) +
                                  " usable");
    try {
      const CvViews cv_views = ToCv(views, used);
      fit = fisheye ? FitFisheye(cv_views, size) : FitPinhole(cv_views, size, options);
    } catch (const cv::Exception& e) {
      throw std::invalid_argument(std::string("OpenCV could not calibrate: ") + e.err);
    }
    if (!fit.beyond_start.empty()) {
      DropViews(
          [&](size_t k) {
            return std::binary_search(fit.beyond_start.begin(), fit.beyond_start.end(), k)
                       ? "corners past 80 deg off axis under the first fit: fisheye::calibrate "
                         "cannot start its poses from them"
                       : std::string();
          },
          &used, &result.images);
      continue;
    }
    for (size_t k = 0; k < used.size(); ++k) result.images[used[k]].rms_px = fit.view_rms[k];
    const double limit = std::max(1.0, options.reject_factor * Median(fit.view_rms));
    const auto too_far = [&](size_t k) {
      if (fit.view_rms[k] <= limit) return std::string();
      char text[128];
      std::snprintf(text, sizeof(text), "corner RMS %.2f px > %.2f px (%.0fx the median image)",
                    fit.view_rms[k], limit, options.reject_factor);
      return std::string(text);
    };
    if (round >= options.max_rounds || !DropViews(too_far, &used, &result.images)) break;
  }
  FillCamera(fit, options.model, width, height, &result);
  std::vector<IntrinsicsView> used_views;
  for (const size_t i : used) used_views.push_back(views[i]);
  result.coverage = MeasureCoverage(used_views, width, height, options);
  result.verdict = Verdict(result, options, &result.good);
  return result;
}

std::string FormatIntrinsics(const IntrinsicsResult& r) {
  std::string text;
  char line[256];
  const CameraModel& c = r.camera;
  std::snprintf(line, sizeof(line), "camera %dx%d, %s: fx %.3f fy %.3f cx %.3f cy %.3f\n", c.width,
                c.height,
                c.type == CameraModelType::kKannalaBrandt ? "kannala-brandt" : "pinhole-radtan",
                c.fx, c.fy, c.cx, c.cy);
  text += line;
  text += "parameter  value  sigma  (1.96 sigma / value)\n";
  for (size_t i = 0; i < r.parameters.size(); ++i) {
    std::snprintf(line, sizeof(line), "  %-4s %14.6g %12.3g  (%s)\n", r.parameter_names[i].c_str(),
                  r.parameters[i], r.sigmas[i],
                  r.parameters[i] != 0.0
                      ? Percent(1.96 * r.sigmas[i] / std::abs(r.parameters[i])).c_str()
                      : "-");
    text += line;
  }
  int used = 0;
  for (const IntrinsicsImage& image : r.images) {
    used += image.used;
    std::snprintf(line, sizeof(line), "  %-24s %3d corners  rms %6.3f px  %s\n", image.name.c_str(),
                  image.corners, image.rms_px,
                  image.used ? "used" : ("not used: " + image.reason).c_str());
    text += line;
  }
  std::snprintf(line, sizeof(line),
                "RMS %.3f px over %d images; coverage: %.0f %% of the %dx%d cells, %.0f %% of "
                "the border\n",
                r.rms_px, used, 100.0 * r.coverage.cells_covered, r.coverage.columns,
                r.coverage.rows, 100.0 * r.coverage.border_covered);
  text += line;
  return text + "verdict: " + r.verdict + "\n";
}

}  // namespace calibench
