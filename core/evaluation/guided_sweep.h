// The guided-capture protocol on simulated data: each new board is held where NextBestPose says
// (perturbed as a hand holds it) or where the simulator's random placement puts it, the pairs go
// through the real pipeline (image detection, LiDAR plane, solve) one at a time, and the stop
// rule decides when to stop. Compared: the pairs each placement needs to reach the goal, and the
// true error when the tool said "done". An evaluation protocol: it drives both the simulator and
// guidance, neither of which depends on the other.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/guidance/next_pose.h"
#include "core/guidance/stop_rule.h"
#include "core/sim/sim.h"

namespace calibench {

struct GuidedSweepOptions {
  SimOptions sim;  // sensors, board, noise, mount, distance range (num_pairs unused)
  CaptureGoal goal;
  StopRuleOptions stop;
  GuidanceOptions guidance;
  PipelineOptions pipeline;
  int seeds = 10;
  std::uint64_t first_seed = 1;
  int max_pairs = 60;                // a run that is not done by then counts as never done
  double hand_translation_m = 0.10;  // the hand's error: uniform in ±this per axis
  double hand_rotation_deg = 10.0;   // and a turn of up to this about a random axis
  int threads = 2;                   // runs in parallel
  bool Check(std::string* why) const;
};

struct GuidedRun {
  std::string placement;  // "guided" or "random"
  std::uint64_t seed = 0;
  int poses = 0;     // boards held until done (or max_pairs)
  int accepted = 0;  // of them accepted by the pipeline
  bool done = false;
  Vec3 error_t_mm = Vec3::Zero();  // true error at the end, camera axes
  Vec3 error_r_deg = Vec3::Zero();
  Vec3 sigma_t_mm = Vec3::Zero();  // reported at the end
  Vec3 sigma_r_deg = Vec3::Zero();
  bool within_goal = false;           // every axis within 3 × the goal
  bool within_sigma = false;          // every axis within 3 × its reported σ
  std::vector<std::string> failures;  // why poses held were not accepted, pose by pose
};

struct GuidedSweepResult {
  GuidedSweepOptions options;
  std::vector<GuidedRun> runs;
};

GuidedSweepResult RunGuidedSweep(const GuidedSweepOptions& options,
                                 const std::function<void(const std::string&)>& log = {});

// One capture, pose by pose (exposed for tests): `guided` chooses the placement.
GuidedRun RunGuidedCapture(const GuidedSweepOptions& options, std::uint64_t seed, bool guided);

// Markdown: per placement, the median poses to done, runs done, within 3× the goal, within 3σ.
std::string FormatGuidedSweepTable(const GuidedSweepResult& result);

}  // namespace calibench
