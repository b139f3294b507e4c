#include "core/session/lrf_calibration_job.h"

#include <utility>

#include "core/lrf/result_io.h"
#include "core/results/pair_status.h"

namespace calibench {
namespace {

std::vector<std::string> PairIds(const LrfDataset& dataset) {
  std::vector<std::string> ids;
  for (const LrfPairEntry& pair : dataset.pairs) ids.push_back(pair.id);
  return ids;
}

// The pairs the user rejected in `session`, by id.
std::set<std::string> RejectedIn(const Session& session) {
  std::set<std::string> rejected;
  for (const PairState& pair : session.pairs)
    if (pair.status == PairStatus::kRejected) rejected.insert(pair.id);
  return rejected;
}

// The reason the user gave for each rejected pair (the extraction marks them "rejected by the
// user").
void GiveRejectionReasons(const Session& session, std::vector<LrfPairFeatures>* pairs) {
  for (LrfPairFeatures& pair : *pairs) {
    if (pair.status != PairStatus::kRejected) continue;
    for (const PairState& state : session.pairs)
      if (state.id == pair.id && !state.reason.empty()) pair.reason = state.reason;
  }
}

}  // namespace

std::filesystem::path DefaultLrfSessionPath(const std::filesystem::path& manifest) {
  std::error_code error;
  const std::filesystem::path folder =
      std::filesystem::is_directory(manifest, error) ? manifest : manifest.parent_path();
  return folder / "calibench.lrf-session.json";
}

Session NewLrfSession(const LrfDataset& dataset, LrfMethod method) {
  Session session;
  session.dataset = NormalizeSessionPath(dataset.manifest);
  session.lrf_method = LrfMethodName(method);
  for (const std::string& id : PairIds(dataset)) session.pairs.emplace_back().id = id;
  return session;
}

LrfSessionWithDataset LoadLrfSessionWithDataset(const std::filesystem::path& session_path) {
  Session session = LoadSession(session_path);
  if (session.lrf_method.empty())
    throw IoError(session_path.string() + ": a LiDAR-camera session of " +
                  session.dataset.string() +
                  ", not a 2D LRF one (no options.lrf_method); `calibench gui --session` and "
                  "`calibench calibrate --session` open it");
  LrfDataset dataset = LoadLrfDataset(session.dataset);
  session = SessionOverPairs(std::move(session), PairIds(dataset), dataset.manifest, session_path);
  return {std::move(session), std::move(dataset)};
}

bool IsLrfSession(const std::filesystem::path& path) {
  if (!IsSessionFile(path)) return false;
  try {
    return !LoadSession(path).lrf_method.empty();
  } catch (const IoError&) {
    return false;
  }
}

SessionResult SessionResultFromLrf(const LrfSolution& solution) {
  SessionResult result;
  result.cam_from_lidar = solution.cam_from_lrf;
  result.covariance = solution.covariance;
  result.iterations = solution.iterations;
  result.converged = solution.converged;
  result.cost_history = solution.cost_history;
  result.weak_directions = solution.observability.weak_directions;
  result.well_constrained = solution.observability.well_constrained;
  for (const IterationReport& it : solution.history) {
    result.step_history.push_back(it.step_norm);
    result.estimate_history.push_back(it.cam_from_lidar);
  }
  if (result.step_history.size() != result.cost_history.size()) {
    // Kept only when they line up with the costs (SessionResult's rule).
    result.step_history.clear();
    result.estimate_history.clear();
  }
  return result;
}

LrfCalibrationJob::LrfCalibrationJob(LrfDataset dataset, LrfPipelineOptions options,
                                     std::optional<Session> saved)
    : extraction_(std::move(dataset), options), options_(std::move(options)) {
  if (!saved) {
    record_.Reset(NewLrfSession(extraction_.dataset(), options_.solver.method));
    return;
  }
  CALIBENCH_CHECK(ParseLrfMethod(saved->lrf_method).has_value());
  // The saved pairs that options.pair_ids selects, in the dataset's order; a selected pair the
  // session lacks joins as pending (LoadLrfSessionWithDataset checked the saved ones are the
  // dataset's).
  std::vector<PairState> pairs;
  for (const std::string& id : PairIds(extraction_.dataset())) {
    const PairState* found = FindPair(&*saved, id);
    if (found) {
      pairs.push_back(*found);
    } else {
      pairs.emplace_back().id = id;
    }
  }
  saved->pairs = std::move(pairs);
  record_.Reset(std::move(*saved));
}

void LrfCalibrationJob::SetRejected(const std::string& pair_id, bool rejected,
                                    const std::string& reason) {
  record_.Edit([&](Session* session) {
    PairState* pair = FindPair(session, pair_id);
    if (!pair) return;
    pair->status = rejected ? PairStatus::kRejected : PairStatus::kPending;
    pair->reason = !rejected ? "" : reason.empty() ? kRejectedByUser : reason;
  });
}

void LrfCalibrationJob::SetMethod(LrfMethod method) {
  record_.Edit([&](Session* session) { session->lrf_method = LrfMethodName(method); });
}

std::set<std::string> LrfCalibrationJob::Rejected() const { return RejectedIn(record_.Current()); }

LrfPipelineOptions LrfCalibrationJob::options() const {
  LrfPipelineOptions options = options_;
  options.solver.method = *ParseLrfMethod(record_.Current().lrf_method);
  return options;
}

std::vector<LrfPairFeatures> LrfCalibrationJob::ExtractedPairs() const {
  const Session word = record_.Current();
  std::vector<LrfPairFeatures> pairs = extraction_.Pairs(RejectedIn(word));
  GiveRejectionReasons(word, &pairs);
  return pairs;
}

const LrfCalibrationOutcome& LrfCalibrationJob::Solve() {
  const Session word = record_.Current();  // one read: the rejections and the method together
  const std::set<std::string> rejected = RejectedIn(word);
  LrfPipelineOptions solved_with = options_;
  solved_with.solver.method = *ParseLrfMethod(word.lrf_method);
  outcome_ = extraction_.Solve(rejected, solved_with);
  GiveRejectionReasons(word, &outcome_->pairs);
  solved_with_ = solved_with;
  std::optional<SessionResult> result;
  if (outcome_->solution && outcome_->solution->ok)
    result = SessionResultFromLrf(*outcome_->solution);
  record_.Edit(
      [&](Session* session) {
        // An edit made while it solved (from another thread) makes this solve not the record's.
        const bool current =
            RejectedIn(*session) == rejected && session->lrf_method == word.lrf_method;
        session->result = current ? result : std::nullopt;
      },
      /*amend=*/true);
  return *outcome_;
}

JobVerdict LrfCalibrationJob::Calibrate() {
  const LrfCalibrationOutcome& outcome = Solve();
  return VerdictOf(
      outcome, [](const LrfSolution& solution) { return solution.cam_from_lrf; },
      FormatLrfSummary(outcome), dataset().cam_from_lrf_ground_truth);
}

void LrfCalibrationJob::WriteResultFile(const std::filesystem::path& path) const {
  CALIBENCH_CHECK(outcome_ && outcome_->solution);
  WriteLrfResult(path, *outcome_, solved_with_);
}

std::unique_ptr<LrfCalibrationJob> OpenLrfJob(const std::filesystem::path& dataset,
                                              const std::filesystem::path& session,
                                              const LrfPipelineOptions& options) {
  CALIBENCH_CHECK(!dataset.empty() || !session.empty());
  if (session.empty()) return std::make_unique<LrfCalibrationJob>(LoadLrfDataset(dataset), options);
  LrfSessionWithDataset opened = LoadLrfSessionWithDataset(session);
  if (!dataset.empty() &&
      NormalizeSessionPath(LoadLrfDataset(dataset).manifest) != opened.session.dataset)
    throw IoError(session.string() + ": the session of " + opened.session.dataset.string() +
                  ", not of " + dataset.string());
  return std::make_unique<LrfCalibrationJob>(std::move(opened.dataset), options,
                                             std::move(opened.session));
}

}  // namespace calibench
