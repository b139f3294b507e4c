// Where a hand puts a board it was asked to hold at a pose (next_pose.h, HandPlacements).
#include <random>

#include "core/guidance/next_pose.h"

namespace calibench {

std::vector<Pose> HandPlacements(const Pose& target, double translation_m, double rotation_deg,
                                 int samples) {
  // The same draws on every call: candidates are compared on equal footing (common random
  // numbers) and `advise` says the same twice.
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Pose> placements;
  placements.reserve(samples);
  for (int k = 0; k < samples; ++k) {
    Pose held = target;
    held.translation() += translation_m * Vec3(unit(rng), unit(rng), unit(rng));
    const Vec3 axis = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
    const double angle = rotation_deg * kDegToRad * std::abs(unit(rng));
    held.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix() * target.linear();
    placements.push_back(held);
  }
  return placements;
}

}  // namespace calibench
