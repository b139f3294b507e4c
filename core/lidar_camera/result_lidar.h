// The result file's LiDAR objects (result_io.cpp writes them; result_lidar.cpp makes them, with
// the summary's lines DescribeLidarModel and DescribeLearnedLidarNoise, result_io.h).
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "core/lidar_camera/pipeline.h"

namespace calibench {

// `lidar_model`: the model most pairs' planes were fitted with, why, and every model's count;
// null without LiDAR fits.
nlohmann::json LidarModelJson(const CalibrationOutcome& outcome);

// `lidar_noise`: the noise learned from the accepted boards fitted along their rays; null when
// none was.
nlohmann::json LidarNoiseJson(const CalibrationOutcome& outcome);

// `lidar_times`: the accepted boards' returns in time (their clouds' per-point times): how many
// pairs carry them, a board's span and its centre after its cloud's stamp; null without fits.
nlohmann::json LidarTimesJson(const CalibrationOutcome& outcome);

}  // namespace calibench
