// One camera's dataset is a rig of one (core/io/rig_folder.h RigOfOne): its rig calibration is
// its camera's own, bit for bit, so `report` and `calibrate --report` read one outcome
// (RigOutcome) whatever the rig's size.
#include <gtest/gtest.h>

#include <string>

#include "core/io/rig_folder.h"
#include "core/lidar_camera/rig.h"
#include "core/session/calibration_job.h"
#include "core/session/job.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

Dataset Simulated(int pairs, const char* name) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = pairs;
  sim.seed = 17;
  return SimulateDataset(sim, test::TempDir(std::string("rig_of_one_") + name) / "sim");
}

TEST(RigOfOne, ItsSolveIsItsCamerasOwnBitForBit) {
  const Dataset dataset = Simulated(8, "eight");
  const RigFolder rig = RigOfOne(dataset);
  ASSERT_EQ(rig.cameras.size(), 1u);
  const RigOutcome outcome = CalibrateRig(rig, PipelineOptions{});
  const CalibrationOutcome alone = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_TRUE(alone.solution) << alone.failure;
  ASSERT_TRUE(outcome.joint.has_value()) << outcome.failure;
  EXPECT_FALSE(outcome.Several());
  EXPECT_EQ(outcome.camera_names, rig.camera_names);
  EXPECT_EQ(outcome.shared_captures, 0);
  ASSERT_EQ(outcome.single.size(), 1u);
  ASSERT_TRUE(outcome.single[0].solution);
  EXPECT_EQ(outcome.single[0].solution->cam_from_lidar.matrix(),
            alone.solution->cam_from_lidar.matrix());
  EXPECT_EQ(outcome.single[0].solution->covariance, alone.solution->covariance);
  ASSERT_EQ(outcome.joint->cam_from_lidar.size(), 1u);
  EXPECT_EQ(outcome.joint->cam_from_lidar[0].matrix(), alone.solution->cam_from_lidar.matrix());
  EXPECT_EQ(Mat6(outcome.joint->covariance), alone.solution->covariance);
  int accepted = 0;
  for (const PairFeatures& pair : alone.pairs) accepted += pair.status == PairStatus::kAccepted;
  EXPECT_EQ(outcome.joint->used_captures, accepted);
  // Its pose and σ as a rig reads them are the camera's (RigJointPose), within the truth's reach.
  const PoseWithSigmas pose = RigJointPose(outcome, 0);
  EXPECT_EQ(pose.name, rig.camera_names[0]);
  EXPECT_TRUE(RigRelativePoses(outcome).empty());
  ASSERT_TRUE(dataset.cam_from_lidar_ground_truth.has_value());
  const PoseError error = ComputePoseError(pose.pose, *dataset.cam_from_lidar_ground_truth);
  EXPECT_LT(error.translation_m, 0.02);
  EXPECT_LT(error.rotation_rad, 0.5 * kDegToRad);
  EXPECT_GT(pose.sigma_t_mm.minCoeff(), 0.0);
  EXPECT_GT(pose.sigma_r_deg.minCoeff(), 0.0);

  // Said as the one camera's job says it (what `calibrate` prints and exits with).
  CalibrationJob job(dataset, CalibrationJobOptions{});
  job.ExtractAll();
  const JobVerdict alone_said = job.Calibrate();
  const std::vector<JobVerdict> said = CameraVerdicts(rig, outcome);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_EQ(said[0].solved, alone_said.solved);
  EXPECT_EQ(said[0].cam_from_source.matrix(), alone_said.cam_from_source.matrix());
  EXPECT_EQ(said[0].covariance, alone_said.covariance);
  EXPECT_EQ(said[0].well_constrained, alone_said.well_constrained);
  ASSERT_EQ(said[0].pairs.size(), alone_said.pairs.size());
  for (size_t i = 0; i < said[0].pairs.size(); ++i) {
    EXPECT_EQ(said[0].pairs[i].id, alone_said.pairs[i].id);
    EXPECT_EQ(said[0].pairs[i].status, alone_said.pairs[i].status);
  }
  ASSERT_TRUE(said[0].ground_truth.has_value());
  EXPECT_EQ(said[0].ground_truth->matrix(), dataset.cam_from_lidar_ground_truth->matrix());
}

TEST(RigOfOne, ACameraThatDoesNotSolveLeavesNoRigSolutionAndSaysWhy) {
  const Dataset dataset = Simulated(2, "two");  // fewer pairs than a solve needs
  const RigFolder rig = RigOfOne(dataset);
  const RigOutcome outcome = CalibrateRig(rig, PipelineOptions{});
  const CalibrationOutcome alone = CalibrateDataset(dataset, PipelineOptions{});
  ASSERT_FALSE(alone.solution);
  EXPECT_FALSE(outcome.joint.has_value());
  ASSERT_EQ(outcome.single.size(), 1u);
  EXPECT_EQ(outcome.single[0].failure, alone.failure);
  EXPECT_EQ(outcome.failure, "camera '" + rig.camera_names[0] + "': " + alone.failure);
  const std::vector<JobVerdict> said = CameraVerdicts(rig, outcome);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_FALSE(said[0].solved);
  EXPECT_EQ(said[0].failure, outcome.failure);
}

}  // namespace
}  // namespace calibench
