// The result file's "intrinsics" section (core/lidar_camera/result_io.h): the camera as estimated
// from the pairs' images first (--estimate-intrinsics), as refined with the extrinsic
// (--refine-intrinsics), or both (the estimate, with the refinement inside it). Private to
// calibench_lidar_camera, which links nlohmann-json privately.
#pragma once

#include <nlohmann/json.hpp>

#include "core/lidar_camera/pipeline.h"

namespace calibench {

// Null when the outcome has neither.
nlohmann::json IntrinsicsJson(const CalibrationOutcome& outcome);

}  // namespace calibench
