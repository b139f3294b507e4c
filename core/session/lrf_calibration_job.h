// The 2D LRF method's calibration job, the counterpart of calibration_job.h: what `calibench
// lrf-calibrate` and the LRF workbench both run. It owns the pairs as extraction finds them
// (core/lrf/pair_extraction.h) and the session's one record (session_record.h): the user's word on
// each pair (a rejection), the LRF method, what the view showed, the last solve, its undo history
// and autosave. Detection and solve read the user's word from the record at every step, so no front
// end copies it in.
//
// An LRF session is a calibench.session.v1 file with "options"."lrf_method" (Session::lrf_method,
// docs/manual.md "2D LRF"): only rejections are the user's word there; the other pairs stay pending
// and extraction decides them again on reopen.
//
// Threads: one thread drives extraction and the solve (the workbench's worker); the record may be
// edited from another (the window's), as it locks itself.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/lrf/pair_extraction.h"
#include "core/session/job.h"
#include "core/session/session_record.h"

namespace calibench {

// Where the LRF workbench keeps a manifest's session unless told: calibench.lrf-session.json beside
// the manifest (not calibench.session.json: a folder may hold a LiDAR-camera dataset too).
std::filesystem::path DefaultLrfSessionPath(const std::filesystem::path& manifest);

// One pending pair per dataset pair, `method`, an empty view.
Session NewLrfSession(const LrfDataset& dataset, LrfMethod method);

// An LRF session file with the dataset it names, its pairs checked to be that dataset's
// (SessionOverPairs). Throws IoError naming the file: a LiDAR-camera session, an unreadable one, or
// one whose pairs are not the manifest's.
struct LrfSessionWithDataset {
  Session session;
  LrfDataset dataset;
};
LrfSessionWithDataset LoadLrfSessionWithDataset(const std::filesystem::path& session_path);

// Whether `path` is an LRF session file (a session with options.lrf_method); false for anything
// that does not read as a session.
bool IsLrfSession(const std::filesystem::path& path);

// The part of an LRF solve the session keeps (SessionResult's cam_from_lidar is cam_from_lrf).
SessionResult SessionResultFromLrf(const LrfSolution& solution);

class LrfCalibrationJob final : public Job {
 public:
  // `dataset`'s pairs that options.pair_ids selects, none extracted yet. The record starts as
  // `saved` (an LRF session of this dataset; its method then replaces options.solver.method), or
  // as a new session with options.solver.method.
  LrfCalibrationJob(LrfDataset dataset, LrfPipelineOptions options,
                    std::optional<Session> saved = std::nullopt);

  std::shared_ptr<const LrfPairFeatures> ExtractPair(int index) {
    return extraction_.ExtractPair(index);
  }

  // The user's word, each one undo step in the record: a rejected pair stays out of the solve
  // until taken back (Job::SetRejected); the method solves from now on.
  void SetRejected(const std::string& pair_id, bool rejected,
                   const std::string& reason = "") override;
  void SetMethod(LrfMethod method);

  // Solves from the extracted pairs with the record's rejections and method; the result becomes
  // the record's last solve (amending the current step: a solve is no edit).
  const LrfCalibrationOutcome& Solve();

  // The pairs as extraction left them, the record's rejections applied; pending until extracted.
  std::vector<LrfPairFeatures> ExtractedPairs() const;
  std::set<std::string> Rejected() const;
  const LrfDataset& dataset() const { return extraction_.dataset(); }
  // The job's options with the record's method.
  LrfPipelineOptions options() const;
  const std::optional<LrfCalibrationOutcome>& outcome() const { return outcome_; }

  // Job: what any front end asks of a job, whatever its method.
  JobKind kind() const override { return JobKind::kLrf; }
  std::filesystem::path manifest() const override { return dataset().manifest; }
  int size() const override { return extraction_.size(); }
  void ExtractAll(const ProgressCallback& progress = {}) override {
    extraction_.ExtractAll(progress);
  }
  JobVerdict Calibrate() override;  // Solve, in the interface's words
  // WriteLrfResult of the last solve with the options it solved with (cam_from_lrf).
  void WriteResultFile(const std::filesystem::path& path) const override;
  SessionRecord& record() override { return record_; }
  const SessionRecord& record() const override { return record_; }

 private:
  LrfPairExtraction extraction_;
  LrfPipelineOptions options_;
  SessionRecord record_;
  std::optional<LrfCalibrationOutcome> outcome_;
  LrfPipelineOptions solved_with_;  // the options of outcome_'s solve (the record's method)
};

// The LRF job that `dataset` and `session` name, as `lrf-calibrate`, `calibrate` and `report`
// take them (either may be empty, not both): a session's rejections and method over its dataset,
// which `dataset`, when given, must be; else a new session over `dataset` with
// options.solver.method. Throws IoError naming the file.
std::unique_ptr<LrfCalibrationJob> OpenLrfJob(const std::filesystem::path& dataset,
                                              const std::filesystem::path& session,
                                              const LrfPipelineOptions& options);

}  // namespace calibench
