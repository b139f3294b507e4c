// A reference calibration (core/results/reference.h), as `evaluate --reference` reads and weighs
// it: an exported transform read back in the frames it was written with gives the pose written
// (<= 1e-12), whichever camera frame and parent; the difference's chi-square is delta^T Sigma^-1
// delta computed by hand for a known perturbation and a diagonal covariance.
#include <gtest/gtest.h>

#include <fstream>

#include "core/results/reference.h"
#include "core/sim/sim.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

TEST(Reference, AnExportReadInItsFramesIsTheCalibrationWritten) {
  const auto dir = test::TempDir("reference_read");
  Pose cam_from_lidar = DefaultCamFromLidar();
  cam_from_lidar.translation() += Vec3(0.012, -0.031, 0.207);
  for (const bool swap : {false, true}) {
    for (const CameraFrame camera_frame : {CameraFrame::kOptical, CameraFrame::kLink}) {
      ExportFrames frames;
      frames.camera_is_parent = swap;
      frames.camera_frame = camera_frame;
      const auto path = dir / (std::string(swap ? "swap_" : "") + CameraFrameName(camera_frame) +
                               "_" + DefaultExportFileName(ExportFormat::kUrdf));
      std::ofstream(path)
          << ExportCalibration(ExportFormat::kUrdf, cam_from_lidar, frames, "test").text;
      std::string how;
      const Pose read = ReadReferenceCamFromLidar(path, frames, &how);
      EXPECT_TRUE(test::MatrixNear(read.matrix(), cam_from_lidar.matrix(), 1e-12)) << how;
      EXPECT_NE(how.find(swap ? "being the parent" : "being the child"), std::string::npos) << how;
      EXPECT_NE(how.find(CameraFrameName(camera_frame)), std::string::npos) << how;
    }
  }
  std::string how;
  EXPECT_THROW(ReadReferenceCamFromLidar(dir / "missing.urdf", ExportFrames{}, &how), IoError);
}

TEST(Reference, TheDifferenceIsWeighedByTheResultsCovariance) {
  const Pose reference = DefaultCamFromLidar();
  Vec6 delta;  // [rho; phi]: 4 mm, -2 mm, 1 mm; 0.2, 0.1, -0.3 degrees
  delta << 0.004, -0.002, 0.001, 0.2 * M_PI / 180, 0.1 * M_PI / 180, -0.3 * M_PI / 180;
  const Pose result = reference * ExpSE3(delta);
  Vec6 sigma;
  sigma << 0.002, 0.002, 0.004, 0.1 * M_PI / 180, 0.1 * M_PI / 180, 0.2 * M_PI / 180;
  const Mat6 covariance = sigma.cwiseAbs2().asDiagonal();
  const ReferenceDifference difference = CompareWithReference(result, covariance, reference);
  // 2^2 + 1 + 0.25^2 + 2^2 + 1 + 1.5^2 = 12.3125
  ASSERT_TRUE(difference.chi_square);
  EXPECT_NEAR(*difference.chi_square, 12.3125, 1e-6);
  const PoseError error = ComputePoseError(result, reference);
  EXPECT_DOUBLE_EQ(difference.error.translation_m, error.translation_m);
  EXPECT_DOUBLE_EQ(difference.error.rotation_rad, error.rotation_rad);
  // delta's translation turned into the reference camera's axes.
  EXPECT_TRUE(test::MatrixNear(difference.translation_in_camera_m,
                               reference.rotation() * delta.head<3>(), 1e-12));
  EXPECT_FALSE(CompareWithReference(result, Mat6::Zero(), reference).chi_square);
}

}  // namespace
}  // namespace calibench
