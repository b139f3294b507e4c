// The Cramér–Rao bound of the extrinsic for a simulated dataset's board observations (the
// information of each plane: core/estimation/fisher_information.h).
//
// Each pair contributes its two plane features; their bound covariances follow from the noise
// models: LiDAR range noise along the rays of the noise-free board returns (the Fisher
// information of FitPlaneRangeMl), and corner noise in pixels through the camera model at the
// true board pose (the Fisher information of planar PnP, mapped to the board plane). The
// extrinsic's information is then Σ Jᵢᵀ Sᵢ⁻¹ Jᵢ of the weighted plane residual at the truth
// (WeightedPlaneInformation). It is the bound for estimators that use the board planes: board
// edges and corners seen by the LiDAR carry information this bound leaves out.
#pragma once

#include <vector>

#include "core/estimation/fisher_information.h"
#include "core/lidar_camera/solver.h"
#include "core/sim/sim.h"

namespace calibench {

// The bound for a simulated dataset's pairs (all, or the indices in `subset`), with the
// simulator's range noise and `corner_sigma_px`. Both noises must be > 0.
struct SimulationBoundInput {
  std::vector<SimPairTruth> pairs;
  CameraModel camera;
  BoardSpec board;
  Pose cam_from_lidar = Pose::Identity();
  double range_sigma_m = 0.0;
  double angular_sigma_rad = 0.0;  // the beam's jitter across the ray (SimOptions)
  double corner_sigma_px = 0.0;
};
SimulationBoundInput MakeSimulationBoundInput(const SimOptions& options, double corner_sigma_px);
// The corner noise of a simulated dataset's images [px]: the mean of the PnP residual-based
// estimates (CameraBoardObservation::corner_sigma_px) over its pairs, since the renderer's noise
// has no closed-form pixel σ. 0 when no pair shows the board.
double MeasureCornerSigma(const Dataset& dataset);
// Per pair: the true planes with their bound covariances (the weighted solver's input at truth).
std::vector<PlanePair> BoundPlanePairs(const SimulationBoundInput& input);
CramerRaoBound SimulationBound(const SimulationBoundInput& input,
                               const std::vector<int>& subset = {});

}  // namespace calibench
