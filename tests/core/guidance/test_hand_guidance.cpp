// core/guidance under a person's hand: suggestions robust to the hand's error, the detector's
// reach learnt from the boards it missed, and the tolerance told with a suggestion.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/guidance/detection_reach.h"
#include "core/guidance/next_pose.h"
#include "tests/core/guidance/guidance_fixtures.h"

namespace calibench {
namespace {

// The share of a hand's placements around `target` (64 draws, ±10 cm, 10°) that the pipeline's
// reach (GuidanceOptions' usable limits) keeps usable: judged here independently of the sampling
// guidance did.
double UsableShareUnderAHand(const SensorGeometry& sensors, const Pose& cam_from_lidar,
                             const Pose& target) {
  GuidanceOptions usable;
  usable.max_incidence_deg = usable.usable_max_incidence_deg;
  usable.min_square_px = usable.usable_min_square_px;
  usable.image_margin_fraction = usable.usable_image_margin_fraction;
  usable.lidar_returns = usable.usable_lidar_returns;
  usable.reach_square_margin = 1.0;
  usable.reach_angle_margin_deg = 0.0;
  usable.keep_to_distance_range = false;
  int ok = 0;
  const std::vector<Pose> placements = HandPlacements(target, 0.10, 10.0, 64);
  for (const Pose& held : placements)
    ok += CheckFeasible(sensors, cam_from_lidar, held, usable).feasible;
  return static_cast<double>(ok) / placements.size();
}

TEST(HandGuidance, PlacementsStayWithinTheHandsError) {
  const Pose target = FacingBoard(Vec3(0.2, -0.1, 2.0), 20);
  const std::vector<Pose> placements = HandPlacements(target, 0.10, 10.0, 200);
  ASSERT_EQ(placements.size(), 200u);
  double largest_offset = 0, largest_turn = 0;
  for (const Pose& held : placements) {
    const Vec3 offset = held.translation() - target.translation();
    EXPECT_LE(offset.cwiseAbs().maxCoeff(), 0.10 + 1e-12);
    const double turn = RotationAngle(held.linear(), target.linear()) * kRadToDeg;
    EXPECT_LE(turn, 10.0 + 1e-9);
    largest_offset = std::max(largest_offset, offset.cwiseAbs().maxCoeff());
    largest_turn = std::max(largest_turn, turn);
  }
  // They fill the tolerance, not a corner of it; and the same draws come back every time.
  EXPECT_GT(largest_offset, 0.09);
  EXPECT_GT(largest_turn, 9.0);
  EXPECT_TRUE(test::MatrixNear(HandPlacements(target, 0.10, 10.0, 200)[7].matrix(),
                               placements[7].matrix(), 0.0));
}

// The VLP-16 rig with an A3 ChArUco after three frontal boards, a tight goal, and options that
// plan for a board held exactly.
class GuidedCharucoRig : public ::testing::Test {
 protected:
  void SetUp() override {
    sensors.board = BoardPreset("charuco-a3");
    ASSERT_NO_FATAL_FAILURE(
        ThreeFrontalBoards(sensors, cam_from_lidar, solver, &pairs, &seen, &solution));
    exact.hand_tolerance_m = 0.0;
    exact.hand_tolerance_deg = 0.0;
  }
  SensorGeometry sensors = Vlp16Sensors();
  const Pose cam_from_lidar = DefaultCamFromLidar();
  SolverOptions solver;
  std::vector<PlanePair> pairs;
  std::vector<Pose> seen;
  SolverResult solution;
  const CaptureGoal goal{0.5, 0.01};
  GuidanceOptions exact;
};

// Boards up to 5 m: the far ones sit at the edge of what the detector can read, where a hand's
// 10 cm and 10° decide whether the pair is lost.
TEST_F(GuidedCharucoRig, TheSuggestionSurvivesTheHandBetterThanTheExactOne) {
  sensors.max_distance_m = 5.0;
  std::string why;
  const auto held_exactly = NextBestPose(sensors, solution, seen, goal, exact, solver, &why);
  ASSERT_TRUE(held_exactly) << why;
  const auto by_hand = NextBestPose(sensors, solution, seen, goal, GuidanceOptions{}, solver, &why);
  ASSERT_TRUE(by_hand) << why;
  const double exact_share =
      UsableShareUnderAHand(sensors, cam_from_lidar, held_exactly->cam_from_board);
  const double hand_share = UsableShareUnderAHand(sensors, cam_from_lidar, by_hand->cam_from_board);
  std::printf("usable under a hand: exact suggestion %.2f, hand-robust suggestion %.2f\n",
              exact_share, hand_share);
  EXPECT_GE(hand_share, 0.9);
  EXPECT_GE(hand_share, exact_share);
  // Its own estimate of that share agrees with the independent one (16 against 64 draws).
  EXPECT_NEAR(by_hand->usable_share, hand_share, 0.2);
  // It still shrinks σ: the expected score under the hand is below today's.
  const double today =
      (TranslationStd(solution.covariance, cam_from_lidar) * 1e3 / goal.translation_mm)
          .squaredNorm() +
      (RotationStdDeg(solution.covariance, cam_from_lidar) / goal.rotation_deg).squaredNorm();
  EXPECT_LT(by_hand->score, 0.9 * today);
  // Told with its tolerance, in words.
  EXPECT_GT(by_hand->tolerance.translation_m, 0.0);
  EXPECT_NE(by_hand->words.find(by_hand->tolerance.words), std::string::npos) << by_hand->words;
}

// A pair whose camera found the board (its PnP pose) or missed it (placed by its LiDAR plane).
PairFeatures Found(const std::string& id, const Pose& cam_from_board) {
  PairFeatures p;
  p.id = id;
  p.status = PairStatus::kAccepted;
  p.camera = CameraBoardObservation{};
  p.camera->cam_from_board = cam_from_board;
  return p;
}
PairFeatures Missed(const std::string& id, const Pose& cam_from_board, const Pose& cam_from_lidar) {
  PairFeatures p;
  p.id = id;
  p.status = PairStatus::kFailed;
  p.reason = "camera: only 2 ChArUco corners (need 6)";
  LidarPlaneFit lidar;
  const Pose lidar_from_board = cam_from_lidar.inverse() * cam_from_board;
  lidar.inlier_centroid = lidar_from_board.translation();
  lidar.plane.normal = -lidar_from_board.linear().col(2);
  lidar.plane.distance = -lidar.plane.normal.dot(lidar.inlier_centroid);
  p.lidar = lidar;
  return p;
}

TEST(DetectionReach, MissesBeyondTheBoardsFoundSetTheReachAndSayWhy) {
  const SensorGeometry sensors = Vlp16Sensors(/*fisheye=*/true);
  const Pose cam_from_lidar = DefaultCamFromLidar();
  std::vector<PairFeatures> pairs;
  for (double z : {1.2, 1.5, 1.8, 2.1})
    pairs.push_back(Found("f" + std::to_string(z), FacingBoard(Vec3(0, 0, z), 15)));
  pairs.push_back(Missed("far", FacingBoard(Vec3(0, 0, 3.2), 10), cam_from_lidar));
  pairs.push_back(Missed("near", FacingBoard(Vec3(0.1, 0, 1.6), 5), cam_from_lidar));
  std::vector<MissedBoard> missed;
  // Without an extrinsic the misses cannot be placed: nothing is learnt.
  DetectionReach reach =
      LearnDetectionReach(sensors.camera, sensors.board, pairs, std::nullopt, {}, &missed);
  EXPECT_EQ(reach.min_square_px, 0.0);
  EXPECT_TRUE(missed.empty());
  reach = LearnDetectionReach(sensors.camera, sensors.board, pairs, cam_from_lidar, {}, &missed);
  const double far_px =
      AppearanceOf(sensors.camera, sensors.board, FacingBoard(Vec3(0, 0, 3.2), 10)).square_px;
  const double smallest_found_px =
      AppearanceOf(sensors.camera, sensors.board, FacingBoard(Vec3(0, 0, 2.1), 15)).square_px;
  ASSERT_LT(far_px, smallest_found_px);
  // The limit sits just past the far miss, never beyond a board found.
  // (Its plane alone places the miss: the in-plane turn is a guess, worth 1 % in the width.)
  EXPECT_NEAR(reach.min_square_px, 1.05 * far_px, 0.02 * far_px);
  EXPECT_LE(reach.min_square_px, smallest_found_px);
  EXPECT_EQ(reach.boards_found, 4);
  EXPECT_EQ(reach.boards_missed, 2);
  ASSERT_EQ(missed.size(), 2u);
  EXPECT_NE(missed[0].words.find("board too small in the image at 3.2 m"), std::string::npos)
      << missed[0].words;
  // A miss inside the reach is not blamed on size: the words say what else it could be.
  EXPECT_NE(missed[1].words.find("within the reach measured"), std::string::npos)
      << missed[1].words;
}

TEST_F(GuidedCharucoRig, AMeasuredReachChangesTheNextSuggestion) {
  // Held exactly, the usable distances 3-5 m: what the detector reads out there decides where the
  // next board can go.
  sensors.min_distance_m = 3.0;
  sensors.max_distance_m = 5.0;
  std::string why;
  const auto first = NextBestPose(sensors, solution, seen, goal, exact, solver, &why);
  ASSERT_TRUE(first) << why;
  // The board held there was missed by the camera (the rig's detector reaches less far than
  // guidance assumed): learnt from that miss, the next suggestion keeps inside the reach.
  std::vector<PairFeatures> features;
  for (const Pose& pose : seen) features.push_back(Found("seen", pose));
  const Pose far = FacingBoard(first->cam_from_board.translation().normalized() * 4.8, 10);
  features.push_back(Missed("missed", far, cam_from_lidar));
  SensorGeometry learnt = sensors;
  learnt.reach = LearnDetectionReach(sensors.camera, sensors.board, features, cam_from_lidar, {});
  const double missed_px = AppearanceOf(sensors.camera, sensors.board, far).square_px;
  const double first_px =
      AppearanceOf(sensors.camera, sensors.board, first->cam_from_board).square_px;
  ASSERT_GT(learnt.reach.min_square_px, missed_px);
  // The first suggestion lies beyond the reach now measured.
  ASSERT_LT(first_px, exact.reach_square_margin * learnt.reach.min_square_px);
  const auto next = NextBestPose(learnt, solution, seen, goal, exact, solver, &why);
  ASSERT_TRUE(next) << why;
  const double next_px =
      AppearanceOf(sensors.camera, sensors.board, next->cam_from_board).square_px;
  std::printf("suggested squares %.1f px; missed at %.1f px; learnt reach %.1f px; next %.1f px\n",
              first_px, missed_px, learnt.reach.min_square_px, next_px);
  EXPECT_GE(next_px, exact.reach_square_margin * learnt.reach.min_square_px - 1e-9);
  EXPECT_TRUE(
      (next->cam_from_board.translation() - first->cam_from_board.translation()).norm() > 0.05 ||
      RotationAngle(next->cam_from_board.linear(), first->cam_from_board.linear()) > 5 * kDegToRad);
}

TEST(HandGuidance, TheGhostMatchesWithinTheSuggestionsOwnTolerance) {
  PoseSuggestion suggestion;
  suggestion.cam_from_board = FacingBoard(Vec3(0, 0, 2.0));
  suggestion.tolerance = {0.10, 10.0, 0.95, "anywhere within a hand's width of it is fine"};
  Pose held = suggestion.cam_from_board;
  held.translation() += Vec3(0.08, -0.05, 0.09);  // 13 cm away, each axis within 10 cm
  EXPECT_TRUE(MatchSuggestion(held, suggestion, GuidanceOptions{}).matches);
  // Where the tilt matters, the same placement does not match.
  suggestion.tolerance = {0.05, 5.0, 0.92, "hold it within 5 cm and 5° of it"};
  const SuggestionMatch tight = MatchSuggestion(held, suggestion, GuidanceOptions{});
  EXPECT_FALSE(tight.matches);
  EXPECT_NE(tight.words.find("within 50 mm per axis and 5 deg counts"), std::string::npos)
      << tight.words;
}

}  // namespace
}  // namespace calibench
