// The result file's "intrinsics" section (core/lidar_camera/result_intrinsics_json.h).
#include "core/lidar_camera/result_intrinsics_json.h"

#include <algorithm>
#include <cmath>

#include "core/camera/camera.h"

namespace calibench {
using nlohmann::json;

namespace {

json CameraParametersJson(const CameraModel& camera) {
  json parameters = json::object();
  const std::vector<std::string> names = IntrinsicParameterNames(camera);
  const std::vector<double> values = IntrinsicParameters(camera);
  for (size_t i = 0; i < names.size(); ++i) parameters[names[i]] = values[i];
  return parameters;
}

// --estimate-intrinsics: the camera the images gave, how well, and whether they were enough.
json EstimatedJson(const IntrinsicsResult& r) {
  const CameraModel& c = r.camera;
  int used = 0;
  for (const IntrinsicsImage& image : r.images) used += image.used;
  return {{"estimated", true},
          {"model", CameraModelName(c.type)},
          {"image_size", {c.width, c.height}},
          {"fx", c.fx},
          {"fy", c.fy},
          {"cx", c.cx},
          {"cy", c.cy},
          {"distortion", c.distortion},
          {"parameter_names", r.parameter_names},
          {"sigmas", r.sigmas},
          {"rms_px", r.rms_px},
          {"images_used", used},
          {"images", static_cast<int>(r.images.size())},
          {"verdict", r.verdict}};
}

// --refine-intrinsics: both cameras, the refined parameters' σ and covariance, how it went.
json RefinementJson(const IntrinsicsRefinement& r) {
  json out = {{"refined", r.failure.empty()},
              {"model", CameraModelName(r.before.type)},
              {"image_size", {r.before.width, r.before.height}},
              {"before", CameraParametersJson(r.before)}};
  if (!r.failure.empty()) {
    out["failure"] = r.failure;
    return out;
  }
  const std::vector<std::string> names = IntrinsicParameterNames(r.after);
  const size_t n = names.size();
  json sigmas = json::object(), held = json::array();
  for (size_t i = 0; i < n; ++i) {
    if (i < r.refined.size() && r.refined[i])
      sigmas[names[i]] = std::sqrt(std::max(0.0, r.after.covariance[i * n + i]));
    else
      held.push_back(names[i]);
  }
  out["after"] = CameraParametersJson(r.after);
  out["sigmas"] = sigmas;
  out["held"] = held;
  out["parameter_names"] = names;
  out["covariance"] = r.after.covariance;
  out["corner_rms_px"] = r.corner_rms_px;
  out["corner_sigma_px"] = r.corner_sigma_px;
  out["pairs"] = r.pairs;
  out["corners"] = r.corners;
  out["edge_points"] = r.edge_points;
  out["iterations"] = r.iterations;
  out["converged"] = r.converged;
  return out;
}

}  // namespace

json IntrinsicsJson(const CalibrationOutcome& outcome) {
  if (!outcome.estimated_intrinsics)
    return outcome.intrinsics_refinement ? RefinementJson(*outcome.intrinsics_refinement) : json();
  json out = EstimatedJson(*outcome.estimated_intrinsics);
  if (outcome.intrinsics_refinement)
    out["refinement"] = RefinementJson(*outcome.intrinsics_refinement);
  return out;
}

}  // namespace calibench
