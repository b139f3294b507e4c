// core/guidance: the stop rule, feasibility, the next pose and its words, the pre-flight checks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "core/estimation/uncertainty.h"
#include "core/guidance/next_pose.h"
#include "core/guidance/preflight.h"
#include "core/guidance/stop_rule.h"
#include "core/sim/sim.h"
#include "tests/core/guidance/guidance_fixtures.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

SolverResult ResultWithSigma(const Vec3& sigma_t_m, const Vec3& sigma_r_rad) {
  SolverResult r;
  r.cam_from_lidar = Pose::Identity();  // camera axes = the perturbation's axes
  r.covariance.setZero();
  r.covariance.diagonal() << sigma_t_m.cwiseAbs2(), sigma_r_rad.cwiseAbs2();
  r.converged = true;
  r.observability.well_constrained = true;
  r.jackknife_pairs = 12;
  r.jackknife_sigma_t_m = 0.5 * sigma_t_m;
  r.jackknife_sigma_r_deg = 0.5 * sigma_r_rad * kRadToDeg;
  return r;
}

TEST(GuidanceStopRule, DoneOnlyWhenEverySigmaIsUnderTheGoalAndTrusted) {
  const CaptureGoal goal{5.0, 0.1};
  StopRuleOptions options;
  const SolverResult good =
      ResultWithSigma(Vec3(0.002, 0.003, 0.0049), Vec3(0.0010, 0.0012, 0.0015));  // 0.086 deg
  CaptureState state = JudgeCapture(good, 12, goal, options);
  EXPECT_TRUE(state.goal_met);
  EXPECT_TRUE(state.trustworthy) << state.trust_note;
  EXPECT_TRUE(state.done);
  EXPECT_NEAR(state.sigma_t_mm.z(), 4.9, 1e-9);

  // One axis over the goal: not done, and the weakest names it.
  SolverResult weak_z = good;
  weak_z.covariance(2, 2) = 0.007 * 0.007;
  state = JudgeCapture(weak_z, 12, goal, options);
  EXPECT_FALSE(state.goal_met);
  EXPECT_FALSE(state.done);
  EXPECT_NE(state.weakest.find("translation along camera z (7.0 mm"), std::string::npos)
      << state.weakest;
  // Rotation the weakest.
  SolverResult weak_r = good;
  weak_r.covariance(4, 4) = std::pow(0.3 * kDegToRad, 2);
  state = JudgeCapture(weak_r, 12, goal, options);
  EXPECT_NE(state.weakest.find("rotation about camera y (0.300 deg"), std::string::npos)
      << state.weakest;

  // Too few pairs: the goal is met but σ is not trusted.
  state = JudgeCapture(good, options.min_pairs - 1, goal, options);
  EXPECT_TRUE(state.goal_met);
  EXPECT_FALSE(state.trustworthy);
  EXPECT_FALSE(state.done);
  EXPECT_NE(state.trust_note.find("trusted from 8 pairs"), std::string::npos) << state.trust_note;

  // The leave-one-out spread larger than the σ: not trusted.
  SolverResult scattered = good;
  scattered.jackknife_sigma_t_m.y() = 2.0 * 0.003;
  state = JudgeCapture(scattered, 12, goal, options);
  EXPECT_FALSE(state.trustworthy);
  EXPECT_NE(state.trust_note.find("2.0× the reported σ"), std::string::npos) << state.trust_note;

  // Not converged, or not constrained: not trusted.
  SolverResult stuck = good;
  stuck.converged = false;
  EXPECT_FALSE(JudgeCapture(stuck, 12, goal, options).trustworthy);
  SolverResult loose = good;
  loose.observability.well_constrained = false;
  EXPECT_FALSE(JudgeCapture(loose, 12, goal, options).trustworthy);
}

TEST(GuidanceFeasibility, EachCheckRefusesWhatItNames) {
  const SensorGeometry sensors = Vlp16Sensors();
  const Pose cam_from_lidar = DefaultCamFromLidar();
  GuidanceOptions options;
  // Frontal, centred, 2 m: feasible, with the VLP-16's rings on it.
  Feasibility f = CheckFeasible(sensors, cam_from_lidar, FacingBoard(Vec3(0, 0, 2.0)), options);
  EXPECT_TRUE(f.feasible) << f.why;
  EXPECT_GE(f.rings, 4);
  EXPECT_GE(f.points, 40);
  // Half out of the image.
  f = CheckFeasible(sensors, cam_from_lidar, FacingBoard(Vec3(1.4, 0, 2.0)), options);
  EXPECT_FALSE(f.feasible);
  EXPECT_NE(f.why.find("leave the image"), std::string::npos) << f.why;
  // Turned 70 degrees.
  f = CheckFeasible(sensors, cam_from_lidar, FacingBoard(Vec3(0, 0, 2.0), 70), options);
  EXPECT_FALSE(f.feasible);
  EXPECT_NE(f.why.find("too oblique to the camera (70 deg"), std::string::npos) << f.why;
  // Beyond the usable distance.
  f = CheckFeasible(sensors, cam_from_lidar, FacingBoard(Vec3(0, 0, 6.0)), options);
  EXPECT_FALSE(f.feasible);
  EXPECT_NE(f.why.find("outside the usable 1.0-4.0 m"), std::string::npos) << f.why;
  // Squares too small at range: 40 mm squares at 4 m in a fisheye of fx 450 are ~4.5 px.
  SensorGeometry fisheye = Vlp16Sensors(/*fisheye=*/true);
  fisheye.max_distance_m = 5.0;
  f = CheckFeasible(fisheye, cam_from_lidar, FacingBoard(Vec3(0, 0, 4.0)), options);
  EXPECT_FALSE(f.feasible);
  EXPECT_NE(f.why.find("squares would be 4 px wide in the image, under 12"), std::string::npos)
      << f.why;
  // Above the VLP-16's ±15° field of view, yet inside the fisheye's image (squares of 9 px
  // allowed here: the check under test is the LiDAR's).
  options.min_square_px = 5;
  f = CheckFeasible(fisheye, cam_from_lidar, FacingBoard(Vec3(0, -0.95, 1.2)), options);
  EXPECT_FALSE(f.feasible);
  EXPECT_NE(f.why.find("too few LiDAR returns"), std::string::npos) << f.why;
  // Without a solution the LiDAR is not judged.
  f = CheckFeasible(fisheye, std::nullopt, FacingBoard(Vec3(0, -0.95, 1.2)), options);
  EXPECT_TRUE(f.feasible) << f.why;
}

TEST(GuidanceFeasibility, BoardReturnsMatchTheSimulatorsScan) {
  const SensorGeometry sensors = Vlp16Sensors();
  const Pose lidar_from_cam = DefaultCamFromLidar().inverse();
  for (const Pose& cam_from_board :
       {FacingBoard(Vec3(0, 0, 2.0)), FacingBoard(Vec3(-0.4, 0.1, 2.5), 30),
        FacingBoard(Vec3(0.3, -0.1, 1.5), -40)}) {
    const Pose lidar_from_board = lidar_from_cam * cam_from_board;
    const BoardReturns predicted = PredictBoardReturns(sensors, lidar_from_board);
    LidarScene scene;
    scene.lidar_from_board = lidar_from_board;
    scene.clutter = false;
    const LidarScan scan =
        SimulateLidarScan(sensors.lidar, BoardPrint(sensors.board), scene, LidarScanOptions{});
    ASSERT_GT(scan.size(), 20u);
    // One ray caster (core/lidar/board_returns.h): the same returns, ray for ray.
    EXPECT_EQ(predicted.points.size(), scan.size());
    // Every ring that crosses the sheet gives two edge crossings.
    EXPECT_GE(predicted.edges.size(), 2u * GuidanceOptions{}.lidar_returns.RingsCovered(predicted));
  }
}

TEST(GuidanceNextPose, TheSuggestionIsFeasibleAndShrinksTheWeakestDirection) {
  const SensorGeometry sensors = Vlp16Sensors();
  const Pose cam_from_lidar = DefaultCamFromLidar();
  GuidanceOptions options;
  // Held exactly: the score is the model's prediction at the pose itself (the hand's error is
  // tested in test_hand_guidance.cpp).
  options.hand_tolerance_m = 0.0;
  options.hand_tolerance_deg = 0.0;
  SolverOptions solver;
  std::vector<PlanePair> pairs;
  std::vector<Pose> seen;
  SolverResult solution;
  ASSERT_NO_FATAL_FAILURE(
      ThreeFrontalBoards(sensors, cam_from_lidar, solver, &pairs, &seen, &solution));
  const CaptureGoal goal{2.0, 0.05};
  std::string why;
  const auto next = NextBestPose(sensors, solution, seen, goal, options, solver, &why);
  ASSERT_TRUE(next) << why;
  EXPECT_TRUE(next->feasibility.feasible);
  EXPECT_TRUE(CheckFeasible(sensors, cam_from_lidar, next->cam_from_board, options).feasible);
  ASSERT_TRUE(next->lidar_from_board);
  // The shown frame: z out of the print towards the sensors, so the LiDAR sees it face on.
  const Vec3 shown_z = next->lidar_from_board->linear().col(2);
  EXPECT_LT(shown_z.dot(next->lidar_from_board->translation()), 0.0);
  // It shrinks the weakest direction, and by more than repeating a board already seen.
  // Σ (σ/goal)² over the six axes, the quantity the suggestion minimises.
  auto goal_score = [&](const Mat6& covariance) {
    return (TranslationStd(covariance, cam_from_lidar) * 1e3 / goal.translation_mm).squaredNorm() +
           (RotationStdDeg(covariance, cam_from_lidar) / goal.rotation_deg).squaredNorm();
  };
  const double before = goal_score(solution.covariance);
  EXPECT_LT(next->score, 0.9 * before);
  // Its predicted σ, recomputed from the planned pair's information, is what it reports.
  BoardReturns next_returns;
  CheckFeasible(sensors, cam_from_lidar, next->cam_from_board, options, &next_returns);
  const Mat6 after =
      (ExpectedPoseInformation(pairs, cam_from_lidar, solver) +
       ExpectedPoseInformation(
           {PlannedPair(sensors, cam_from_lidar, next->cam_from_board, next_returns)},
           cam_from_lidar, solver))
          .inverse();
  EXPECT_NEAR(goal_score(after), next->score, 1e-6 * before);
  EXPECT_TRUE(test::MatrixNear(TranslationStd(after, cam_from_lidar) * 1e3,
                               next->predicted_sigma_t_mm, 1e-9));
  // Better than repeating a board already seen.
  BoardReturns repeat_returns;
  CheckFeasible(sensors, cam_from_lidar, seen[0], options, &repeat_returns);
  const Mat6 repeated =
      (ExpectedPoseInformation(pairs, cam_from_lidar, solver) +
       ExpectedPoseInformation({PlannedPair(sensors, cam_from_lidar, seen[0], repeat_returns)},
                               cam_from_lidar, solver))
          .inverse();
  EXPECT_LT(next->score, goal_score(repeated));
  EXPECT_FALSE(next->words.empty());
}

// Every edge point of a pair shares the camera's board-pose error (the sheet's position and turn
// in its plane come from the PnP): modelled as independent per point, a pair's tens of edge
// points claim that error tens of times over and σ comes out too narrow. Here the LiDAR is
// nearly exact and each camera pose is drawn from its own covariance: with the shared error
// eliminated (SolverOptions::edge_board_pose_uncertainty) the normalised squared error comes
// near the pose's 6 degrees of freedom (8.7 here: the plane's and the in-plane parts of one PnP
// pose's error are correlated, which the model treats apart); without it, 22.
TEST(EdgeModel, TheCamerasBoardPoseErrorIsSharedByEveryEdgePoint) {
  SimOptions sim;
  sim.lidar = LidarModel::kOs0_128;
  sim = ResolveSimOptions(sim);
  SensorGeometry sensors = Vlp16Sensors();
  sensors.camera = sim.camera;
  sensors.lidar = MakeBeamTable(LidarModel::kOs0_128);
  sensors.range_sigma_m = 1e-4;  // the camera's error dominates
  sensors.corner_sigma_px = 0.3;
  std::vector<PlanePair> truth;
  for (const double depth : {1.6, 2.2, 2.8})
    for (const double x : {-0.5, 0.0, 0.5})
      for (const double yaw : {-30.0, 25.0}) {
        const Pose cam_from_board = FacingBoard(Vec3(x, 0.1 * x, depth), yaw + 10 * x);
        BoardReturns returns;
        if (!CheckFeasible(sensors, sim.cam_from_lidar, cam_from_board, GuidanceOptions{}, &returns)
                 .feasible)
          continue;
        truth.push_back(PlannedPair(sensors, sim.cam_from_lidar, cam_from_board, returns));
      }
  ASSERT_GE(truth.size(), 10u);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  const auto mean_nees = [&](bool shared_pose_error) {
    SolverOptions options;
    options.edge_board_pose_uncertainty = shared_pose_error;
    options.jackknife_covariance = false;
    options.sandwich_covariance = false;
    // The model's covariance at the true features (variance factors 1): what σ claims.
    const Mat6 covariance =
        ExpectedPoseInformation(truth, sim.cam_from_lidar, options, 1.0, 1.0).inverse();
    const Eigen::LLT<Mat6> whiten(covariance);
    double sum = 0.0;
    const int trials = 60;
    for (int trial = 0; trial < trials; ++trial) {
      std::vector<PlanePair> pairs = truth;
      for (PlanePair& pair : pairs) {
        Vec6 z;
        for (int i = 0; i < 6; ++i) z[i] = normal(rng);
        const Vec6 xi = Eigen::LLT<Mat6>(pair.camera_pose_covariance).matrixL() * z;
        pair.camera_from_board = pair.camera_from_board * ExpSE3(xi);
        const Vec3 n = -pair.camera_from_board.linear().col(2);
        pair.camera_plane = Plane{n, -n.dot(pair.camera_from_board.translation())};
      }
      PlaneAlignmentSolver solver(pairs, options, sim.cam_from_lidar);
      const SolverResult result = solver.Run();
      const Pose error = sim.cam_from_lidar.inverse() * result.cam_from_lidar;
      const Vec6 delta = LogSE3(error);
      sum += delta.dot(whiten.solve(delta));
    }
    return sum / trials;
  };
  const double with_shared = mean_nees(true);
  const double without = mean_nees(false);
  std::printf(
      "%zu pairs: mean normalised squared error %.2f with the shared pose error, %.2f "
      "without (6 = calibrated)\n",
      truth.size(), with_shared, without);
  EXPECT_GT(with_shared, 3.0);
  EXPECT_LT(with_shared, 10.5);
  EXPECT_GT(without, 2.0 * with_shared);
}

TEST(GuidanceNextPose, WithoutASolutionItSuggestsACameraFeasiblePose) {
  const SensorGeometry sensors = Vlp16Sensors();
  std::string why;
  const auto first = NextBestPose(sensors, std::nullopt, {}, CaptureGoal{}, GuidanceOptions{},
                                  SolverOptions{}, &why);
  ASSERT_TRUE(first) << why;
  EXPECT_FALSE(first->lidar_from_board);
  EXPECT_NE(first->words.find("keep it upright"), std::string::npos) << first->words;
  // The second differs from the first.
  const auto second = NextBestPose(sensors, std::nullopt, {first->cam_from_board}, CaptureGoal{},
                                   GuidanceOptions{}, SolverOptions{}, &why);
  ASSERT_TRUE(second) << why;
  EXPECT_GT((second->cam_from_board.translation() - first->cam_from_board.translation()).norm() +
                RotationAngle(second->cam_from_board.linear(), first->cam_from_board.linear()),
            0.3);
}

// While the intrinsics are estimated, the next pose also puts corners where the image has none
// (here: the right quarter of the image, the two right columns of an 8x6 grid; the outermost
// column alone a board reaches, whole and seen by 4 rings, only between about 2 and 3 m).
TEST(GuidanceNextPose, ItAlsoCoversTheImageCellsTheIntrinsicsLack) {
  const SensorGeometry sensors = Vlp16Sensors();
  const Pose cam_from_lidar = DefaultCamFromLidar();
  SolverOptions solver;
  std::vector<PlanePair> pairs;
  std::vector<Pose> seen;
  SolverResult solution;
  ASSERT_NO_FATAL_FAILURE(
      ThreeFrontalBoards(sensors, cam_from_lidar, solver, &pairs, &seen, &solution));
  const double w = sensors.camera.width, h = sensors.camera.height;
  GuidanceOptions options;
  options.image_columns = options.image_rows = 5;
  for (int i = 6; i < 8; ++i)
    for (int j = 0; j < 6; ++j)
      options.intrinsics_cells_to_cover.emplace_back(Vec2(w * i / 8, h * j / 6),
                                                     Vec2(w * (i + 1) / 8, h * (j + 1) / 6));
  auto cells_hit = [&](const Pose& cam_from_board) {
    std::set<int> hit;
    for (const Vec3& corner : BoardCornerPoints(sensors.board)) {
      const auto pixel = sensors.camera.Project(cam_from_board * corner);
      if (!pixel) continue;
      for (size_t k = 0; k < options.intrinsics_cells_to_cover.size(); ++k)
        if (options.intrinsics_cells_to_cover[k].contains(*pixel)) hit.insert(static_cast<int>(k));
    }
    return static_cast<int>(hit.size());
  };
  std::string why;
  const auto next =
      NextBestPose(sensors, solution, seen, CaptureGoal{2.0, 0.05}, options, solver, &why);
  ASSERT_TRUE(next) << why;
  EXPECT_GE(next->intrinsics_cells_covered, 1);
  EXPECT_EQ(next->intrinsics_cells_covered, cells_hit(next->cam_from_board));
  EXPECT_NE(next->words.find("image cells the intrinsics still lack"), std::string::npos)
      << next->words;
  // Without the intrinsics' wish the suggestion stays where the extrinsic gains most: it covers
  // fewer of those cells.
  GuidanceOptions extrinsic_only = options;
  extrinsic_only.intrinsics_cells_to_cover.clear();
  const auto plain =
      NextBestPose(sensors, solution, seen, CaptureGoal{2.0, 0.05}, extrinsic_only, solver, &why);
  ASSERT_TRUE(plain) << why;
  EXPECT_LT(cells_hit(plain->cam_from_board), next->intrinsics_cells_covered);
  EXPECT_EQ(plain->words.find("intrinsics"), std::string::npos);
  // Without a solution too.
  const auto starter =
      NextBestPose(sensors, std::nullopt, {}, CaptureGoal{}, options, solver, &why);
  ASSERT_TRUE(starter) << why;
  EXPECT_GE(starter->intrinsics_cells_covered, 1);
}

TEST(GuidanceWords, DescribeWhatTheGeometryIs) {
  const CameraModel camera = DefaultSimCamera(false);
  for (double yaw : {-30.0, 30.0}) {
    // Left third of the image at 2.5 m.
    const Pose pose = FacingBoard(Vec3(-0.75, 0.0, 2.5), yaw);
    const std::string words = DescribeBoardPose(camera, pose);
    EXPECT_NE(words.find("about 2.6 m away"), std::string::npos) << words;
    EXPECT_NE(words.find("left third of the image"), std::string::npos) << words;
    EXPECT_NE(words.find("~30° about its vertical axis"), std::string::npos) << words;
    // Which edge is nearer, measured: the sheet's left end (smaller image x) against its right.
    const Vec3 a = pose * Vec3(-0.2, 0, 0), b = pose * Vec3(0.2, 0, 0);
    const bool a_is_left = a.x() / a.z() < b.x() / b.z();
    const double left_depth = a_is_left ? a.z() : b.z(), right_depth = a_is_left ? b.z() : a.z();
    const char* expected = left_depth < right_depth ? "(left edge nearer)" : "(right edge nearer)";
    EXPECT_NE(words.find(expected), std::string::npos) << words;
    EXPECT_NE(words.find("keep it upright"), std::string::npos) << words;
  }
  // Rotated in its plane: a diamond.
  Pose diamond = FacingBoard(Vec3(0, 0, 2.0));
  diamond.linear() =
      diamond.linear() * Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()).toRotationMatrix();
  const std::string words = DescribeBoardPose(camera, diamond);
  EXPECT_NE(words.find("~45°"), std::string::npos) << words;
  EXPECT_NE(words.find("(a diamond)"), std::string::npos) << words;
  EXPECT_NE(words.find("centre of the image"), std::string::npos) << words;
}

// A pair as the pipeline would give it: the board at cam_from_board, the LiDAR plane where the
// solution puts it.
PairFeatures PairAt(const std::string& id, const Pose& cam_from_board, const Pose& cam_from_lidar) {
  PairFeatures p;
  p.id = id;
  p.status = PairStatus::kAccepted;
  CameraBoardObservation camera;
  camera.pose_covariance = Mat6::Zero();
  camera.cam_from_board = cam_from_board;
  const Vec3 n = -cam_from_board.linear().col(2);
  camera.plane = Plane{n, -n.dot(cam_from_board.translation())};
  camera.plane_covariance = Mat4::Identity() * 1e-8;
  p.camera = camera;
  LidarPlaneFit lidar;
  const Pose lidar_from_board = cam_from_lidar.inverse() * cam_from_board;
  const Vec3 nl = -lidar_from_board.linear().col(2);
  lidar.plane = Plane{nl, -nl.dot(lidar_from_board.translation())};
  lidar.covariance = Mat4::Identity() * 1e-8;
  lidar.inlier_centroid = lidar_from_board.translation();
  lidar.num_rings = 6;
  p.lidar = lidar;
  p.edge_width_px = 2.0;
  return p;
}

std::vector<std::string> Checks(const std::vector<PreflightFinding>& findings) {
  std::vector<std::string> checks;
  for (const PreflightFinding& f : findings) checks.push_back(f.check);
  return checks;
}

TEST(GuidancePreflight, EachReasonIsFoundAndSaidInWords) {
  const CameraModel camera = DefaultSimCamera(false);
  const BoardSpec board = BoardPreset("a3");
  const Pose cam_from_lidar = DefaultCamFromLidar();
  PipelineOptions pipeline;
  PreflightOptions options;
  auto run = [&](const PairFeatures& pair, const std::vector<PairFeatures>& earlier,
                 std::optional<double> stamps = std::nullopt) {
    PreflightInputs in;
    in.pair = &pair;
    in.camera = &camera;
    in.board = &board;
    in.cam_from_lidar = cam_from_lidar;
    in.earlier = &earlier;
    in.pipeline = &pipeline;
    in.stamp_offset_s = stamps;
    return PreflightPair(in, options);
  };
  const PairFeatures clean = PairAt("a", FacingBoard(Vec3(0, 0, 2.0), 20), cam_from_lidar);
  EXPECT_TRUE(run(clean, {}).empty());

  PairFeatures cut = PairAt("b", FacingBoard(Vec3(1.25, 0, 2.0)), cam_from_lidar);
  auto findings = run(cut, {});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"image-border"});
  EXPECT_EQ(findings[0].severity, PreflightSeverity::kWeak);
  EXPECT_NE(findings[0].words.find("cut by the image border"), std::string::npos);

  PairFeatures two_rings = clean;
  two_rings.lidar->num_rings = 2;
  findings = run(two_rings, {});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"rings"});
  EXPECT_EQ(findings[0].severity, PreflightSeverity::kReject);
  EXPECT_NE(findings[0].words.find("only 2 LiDAR rings on the sheet"), std::string::npos);

  const PairFeatures oblique = PairAt("c", FacingBoard(Vec3(0, 0, 2.0), 65), cam_from_lidar);
  findings = run(oblique, {});
  ASSERT_FALSE(findings.empty());
  EXPECT_EQ(findings[0].check, "oblique");
  EXPECT_NE(findings[0].words.find("too oblique to the camera (65 deg"), std::string::npos);

  PairFeatures blurred = clean;
  blurred.edge_width_px = 6.5;
  findings = run(blurred, {});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"blur"});
  EXPECT_NE(findings[0].words.find("6.5 px wide"), std::string::npos);

  findings = run(clean, {}, 0.12);
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"stamps"});
  EXPECT_NE(findings[0].words.find("120 ms apart"), std::string::npos);

  // The LiDAR saw the board 5 degrees turned from where the camera saw it.
  PairFeatures moved = clean;
  moved.lidar->plane.normal = ExpSO3(Vec3(0, 0, 5 * kDegToRad)) * moved.lidar->plane.normal;
  findings = run(moved, {});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"moved"});
  EXPECT_NE(findings[0].words.find("the board moved between the two sensors"), std::string::npos);

  const PairFeatures again = PairAt("d", FacingBoard(Vec3(0.02, 0, 2.0), 21), cam_from_lidar);
  findings = run(again, {clean});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"duplicate"});
  EXPECT_NE(findings[0].words.find("adds almost nothing"), std::string::npos);
  EXPECT_NE(findings[0].words.find("pair a"), std::string::npos);

  // A wave's sweeps come near each other by design: not duplicates of one another, though a wave
  // passing a hold's pose is; its blur asks for a slower wave, not a still board.
  auto waved = [](PairFeatures pair) {
    TimedObservation frame{0.0, *pair.camera};
    pair.camera_track = {frame, frame};
    pair.camera_track[1].stamp_s = 0.1;
    return pair;
  };
  EXPECT_TRUE(run(waved(again), {waved(clean)}).empty());
  EXPECT_EQ(Checks(run(waved(again), {clean})), std::vector<std::string>{"duplicate"});
  PairFeatures waved_blur = waved(clean);
  waved_blur.edge_width_px = 6.5;
  findings = run(waved_blur, {});
  ASSERT_EQ(Checks(findings), std::vector<std::string>{"blur"});
  EXPECT_NE(findings[0].words.find("wave it slower"), std::string::npos);
}

TEST(GuidancePreflight, BlurIsMeasuredOnTheImage) {
  const CameraModel camera = DefaultSimCamera(false);
  const BoardSpec board = BoardPreset("a3");
  const Pose pose = FacingBoard(Vec3(0, 0, 1.5), 15);
  const ImageU8 sharp = RenderBoardImage(camera, board, pose, RenderOptions{});
  // A horizontal smear of 9 px: the board moved during the exposure.
  ImageU8 smeared = sharp;
  for (int y = 0; y < sharp.height; ++y)
    for (int x = 0; x < sharp.width; ++x) {
      int sum = 0, n = 0;
      for (int k = -4; k <= 4; ++k) {
        const int xx = std::clamp(x + k, 0, sharp.width - 1);
        sum += sharp.Row(y)[xx * sharp.channels];
        ++n;
      }
      for (int c = 0; c < sharp.channels; ++c) smeared.Row(y)[x * sharp.channels + c] = sum / n;
    }
  std::string why;
  const auto detection = DetectBoard(sharp, board, BoardDetectionOptions{}, &why);
  ASSERT_TRUE(detection) << why;
  const auto sharp_width = ChessboardEdgeWidthPx(sharp, board, *detection);
  const auto smeared_width = ChessboardEdgeWidthPx(smeared, board, *detection);
  ASSERT_TRUE(sharp_width && smeared_width);
  std::printf("edge width: sharp %.2f px, smeared %.2f px\n", *sharp_width, *smeared_width);
  EXPECT_LT(*sharp_width, PreflightOptions{}.max_edge_width_px);
  EXPECT_GT(*smeared_width, PreflightOptions{}.max_edge_width_px);
}

}  // namespace
}  // namespace calibench
