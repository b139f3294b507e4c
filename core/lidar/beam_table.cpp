#include "core/lidar/beam_table.h"

#include <algorithm>
#include <cmath>

#include "core/base/names.h"

namespace calibench {
namespace {

// n angles from first_deg to last_deg inclusive, in radians.
std::vector<double> LinspaceDeg(double first_deg, double last_deg, int n) {
  std::vector<double> out(n);
  for (int i = 0; i < n; ++i) {
    out[i] = (first_deg + (last_deg - first_deg) * i / (n - 1)) * kDegToRad;
  }
  return out;
}

constexpr EnumName<LidarModel> kLidarModelNames[] = {
    {LidarModel::kHdl64, "hdl64"},     {LidarModel::kVlp16, "vlp16"},
    {LidarModel::kOs0_128, "os0-128"}, {LidarModel::kSwept2d, "swept-2d"},
    {LidarModel::kMid40, "mid40"},     {LidarModel::kAvia, "avia"},
    {LidarModel::kMid360, "mid360"},   {LidarModel::kNodding2d, "nodding-2d"}};

}  // namespace

std::string LidarModelName(LidarModel model) { return NameIn(kLidarModelNames, model); }

std::optional<LidarModel> ParseLidarModelName(const std::string& name) {
  return ValueIn(kLidarModelNames, name);
}

std::string LidarModelNames() { return NamesIn(kLidarModelNames); }

BeamTable MakeBeamTable(LidarModel model) {
  BeamTable table;
  switch (model) {
    case LidarModel::kHdl64: {
      // HDL-64E S2: lower block of 32 lasers at 1/2 deg, upper block of 32 at ~1/3 deg;
      // 0.1728 deg azimuth resolution at 10 Hz.
      table.elevations_rad = LinspaceDeg(-24.33, -8.83, 32);
      const std::vector<double> upper = LinspaceDeg(-8.33, 2.0, 32);
      table.elevations_rad.insert(table.elevations_rad.end(), upper.begin(), upper.end());
      table.azimuth_steps = 2083;
      table.max_range_m = 120.0;
      break;
    }
    case LidarModel::kVlp16:
      table.elevations_rad = LinspaceDeg(-15.0, 15.0, 16);
      table.azimuth_steps = 1800;  // 0.2 deg at 10 Hz
      table.max_range_m = 100.0;
      break;
    case LidarModel::kOs0_128:
      table.elevations_rad = LinspaceDeg(-45.0, 45.0, 128);
      table.azimuth_steps = 1024;
      table.max_range_m = 50.0;
      break;
    case LidarModel::kSwept2d:
      // A SICK LMS400-like scanner (70° fan, 0.2° resolution) turned by a stage in 0.4° steps,
      // its mirror 10 cm in front of and 5 cm above the stage's axis (the scanner's box sits on
      // it).
      table.elevations_rad = LinspaceDeg(-35.0, 35.0, 351);
      table.azimuth_steps = 900;
      table.max_range_m = 10.0;
      table.swept = true;
      table.mirror_offset_m = Vec3(0.10, 0.0, 0.05);
      break;
    case LidarModel::kNodding2d:
      // A 28° fan at 0.1° (a line scanner's window on the room) tilted through ±20° in 0.1°
      // steps, its mirror 3 cm in front of and 4 cm above the tilt axis.
      table.elevations_rad = LinspaceDeg(-14.0, 14.0, 281);
      table.azimuth_steps = 401;
      table.max_range_m = 20.0;
      table.swept = true;
      table.nodding = true;
      table.tilt_first_rad = -20.0 * kDegToRad;
      table.tilt_last_rad = 20.0 * kDegToRad;
      table.mirror_offset_m = Vec3(0.03, 0.0, 0.04);
      break;
    case LidarModel::kMid40:
    case LidarModel::kAvia:
    case LidarModel::kMid360:
      table.risley = MakeRisleyPattern(LidarModelName(model));
      table.max_range_m = table.risley->max_range_m;
      break;
  }
  return table;
}

int LearntRayCells::CellOf(const Vec3& unit) {
  const double azimuth = std::atan2(unit.y(), unit.x()) * 180.0 / M_PI + 180.0;  // [0, 360]
  const double elevation = std::asin(std::clamp(unit.z(), -1.0, 1.0)) * 180.0 / M_PI + 90.0;
  const int a = std::clamp(static_cast<int>(azimuth), 0, 359);
  const int e = std::clamp(static_cast<int>(elevation), 0, 179);
  return e * 360 + a;
}

BeamTable LearntRayTable(const std::vector<Vec3>& returns) {
  BeamTable table;
  auto rays = std::make_shared<std::vector<Vec3>>();
  rays->reserve(returns.size());
  for (const Vec3& point : returns) {
    const double range = point.norm();
    if (!std::isfinite(range) || range < 0.01) continue;
    rays->push_back(point / range);
  }
  // Counting sort by cell: each cell's rays stay in firing order.
  auto cells = std::make_shared<LearntRayCells>();
  std::vector<int> cell_of(rays->size());
  cells->start.assign(LearntRayCells::kCells + 1, 0);
  for (size_t k = 0; k < rays->size(); ++k) {
    cell_of[k] = LearntRayCells::CellOf((*rays)[k]);
    ++cells->start[cell_of[k] + 1];
  }
  for (int c = 0; c < LearntRayCells::kCells; ++c) cells->start[c + 1] += cells->start[c];
  cells->by_cell.resize(rays->size());
  std::vector<int> next(cells->start.begin(), cells->start.end() - 1);
  for (size_t k = 0; k < rays->size(); ++k)
    cells->by_cell[next[cell_of[k]]++] = static_cast<int>(k);
  table.rays = std::move(rays);
  table.ray_cells = std::move(cells);
  return table;
}

bool BeamTable::InField(const Vec3& direction) const {
  const Vec3 d = direction.normalized();
  if (risley) return InRisleyField(*risley, d);
  if (rays && ray_cells) {
    // A cell without a learnt ray may lie between two strokes: its neighbours count.
    const int cell = LearntRayCells::CellOf(d), e = cell / 360, a = cell % 360;
    for (int de = -1; de <= 1; ++de)
      for (int da = -1; da <= 1; ++da) {
        const int ne = e + de;
        if (ne < 0 || ne >= 180) continue;
        if (ray_cells->Occupied(ne * 360 + (a + da + 360) % 360)) return true;
      }
    return false;
  }
  if (elevations_rad.empty()) return false;
  const auto [lowest, highest] = std::minmax_element(elevations_rad.begin(), elevations_rad.end());
  if (nodding) {
    // d = Ry(tilt) (cos a, sin a, 0) = (cos t cos a, sin a, -sin t cos a).
    const double fan = std::asin(std::clamp(d.y(), -1.0, 1.0));
    const double tilt = std::atan2(-d.z(), d.x());
    return d.x() > 0 && fan >= *lowest && fan <= *highest &&
           tilt >= std::min(tilt_first_rad, tilt_last_rad) &&
           tilt <= std::max(tilt_first_rad, tilt_last_rad);
  }
  const double elevation = std::atan2(d.z(), std::hypot(d.x(), d.y()));
  return elevation >= *lowest && elevation <= *highest;
}

double BeamTable::PhaseSpanRad() const {
  if (risley) return 2.0 * M_PI;
  if (rays) return 0.0;  // the learnt rays are one integration, fired once
  if (nodding)
    return azimuth_steps > 1 ? std::abs(tilt_last_rad - tilt_first_rad) / (azimuth_steps - 1) : 0.0;
  return azimuth_steps > 0 ? 2.0 * M_PI / azimuth_steps : 0.0;
}

}  // namespace calibench
