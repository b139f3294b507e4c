// The session's one record (core/session/session_record.h): the user's word, undo and autosave in
// one place, which the calibration job reads and a front end edits from another thread.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "core/session/calibration_job.h"
#include "core/session/session_record.h"
#include "tests/sim_scenes.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

Session ThreePairs() {
  Session session;
  session.dataset = "/data/set";
  for (const char* id : {"a", "b", "c"}) {
    session.pairs.emplace_back();
    session.pairs.back().id = id;
  }
  return session;
}

TEST(SessionRecord, EditsUndoAndRedoAndPairsThatJoinedSinceStay) {
  SessionRecord record(ThreePairs());
  EXPECT_FALSE(record.CanUndo());
  record.Edit([](Session* s) { s->pairs[0].status = PairStatus::kRejected; });
  record.Edit([](Session* s) { s->pairs[1].brush = BrushMask{4, 8, {1, 2}}; });
  // The later dabs of one stroke amend its step.
  record.Edit([](Session* s) { s->pairs[1].brush->pixels.push_back(3); }, /*amend=*/true);
  // A pair that joins a followed capture is no one's edit.
  record.AddPair("d");
  record.AddPair("d");
  EXPECT_EQ(record.Current().pairs.size(), 4u);

  std::string reason;
  EXPECT_TRUE(record.Rejected("a", &reason));
  EXPECT_EQ(reason, kRejectedByUser);  // none given: the user's
  EXPECT_FALSE(record.Rejected("b"));
  EXPECT_FALSE(record.Rejected("nobody"));
  ASSERT_TRUE(record.EditOf("b").brush_pixels);
  EXPECT_EQ(*record.EditOf("b").brush_pixels, (std::vector<int>{1, 2, 3}));

  // One undo takes the whole stroke back, and keeps the pair that joined since.
  std::optional<Session> undone = record.Undo();
  ASSERT_TRUE(undone);
  EXPECT_FALSE(undone->pairs[1].brush);
  ASSERT_EQ(undone->pairs.size(), 4u);
  EXPECT_EQ(undone->pairs[3].id, "d");
  EXPECT_EQ(record.Current(), *undone);
  EXPECT_FALSE(record.EditOf("b").brush_pixels);
  EXPECT_TRUE(record.Rejected("a"));
  ASSERT_TRUE(record.Undo());
  EXPECT_FALSE(record.Rejected("a"));
  EXPECT_FALSE(record.Undo());  // nothing left
  ASSERT_TRUE(record.Redo());
  ASSERT_TRUE(record.Redo());
  EXPECT_EQ(*record.EditOf("b").brush_pixels, (std::vector<int>{1, 2, 3}));
  EXPECT_FALSE(record.CanRedo());

  // An adjustment is no step: a brush that does not fit its cloud any more is dropped.
  record.Adjust([](Session* s) { s->pairs[1].brush.reset(); });
  EXPECT_FALSE(record.EditOf("b").brush_pixels);
  EXPECT_TRUE(record.CanUndo());
  ASSERT_TRUE(record.Undo());
  EXPECT_FALSE(record.EditOf("b").brush_pixels);  // the step before the stroke
  // A seed's picture is not the user's word.
  record.Edit([](Session* s) {
    s->pairs[2].brush = BrushMask{4, 8, {5}};
    s->pairs[2].brush_from_seed = true;
  });
  EXPECT_FALSE(record.EditOf("c").brush_pixels);
  EXPECT_EQ(record.Edits().count("c"), 0u);
}

TEST(SessionRecord, AutosavesWhenItChangedAndSavesAsAnotherFile) {
  const auto dir = test::TempDir("session_record_autosave");
  SessionRecord record(ThreePairs());
  record.Autosave();  // no file: nothing to do
  EXPECT_FALSE(std::filesystem::exists(dir / "s.json"));
  record.AutosaveTo(dir / "s.json");
  record.Autosave();
  EXPECT_EQ(LoadSession(dir / "s.json"), record.Current());
  record.Edit([](Session* s) { s->settings.huber_delta = 0.25; });
  record.Autosave();
  EXPECT_EQ(LoadSession(dir / "s.json").settings.huber_delta, 0.25);

  record.SaveAs(dir / "other.json");
  record.Edit([](Session* s) { s->settings.max_iterations = 7; });
  record.Autosave();
  EXPECT_EQ(LoadSession(dir / "other.json").settings.max_iterations, 7);
  EXPECT_NE(LoadSession(dir / "s.json").settings.max_iterations,
            7);  // that file is no longer written

  record.AutosaveTo(dir / "missing" / "folder" / "s.json");
  EXPECT_THROW(record.Autosave(), IoError);
  EXPECT_EQ(record.Current().settings.max_iterations, 7);  // the failed write loses nothing
}

// The workbench edits the record on its UI thread while the job reads it on the worker: every read
// sees one whole state, never half of an edit (and ThreadSanitizer sees the lock).
TEST(SessionRecord, ReadersSeeWholeEditsWhileAnotherThreadEdits) {
  Session start = ThreePairs();
  start.settings.max_iterations = 0;  // the edits count from 1
  SessionRecord record(start);
  std::atomic<bool> done{false};
  std::thread editor([&] {
    for (int i = 1; i <= 2000; ++i)
      record.Edit([i](Session* s) {
        // One edit moves both together: a reader must never see them disagree.
        s->settings.max_iterations = i;
        s->pairs[0].brush = BrushMask{1, 4000, std::vector<int>(i % 50, i)};
        s->pairs[0].status = i % 2 ? PairStatus::kRejected : PairStatus::kAccepted;
        s->pairs[0].reason = std::to_string(i);
      });
    done = true;
  });
  int reads = 0, torn = 0;
  while (!done || reads == 0) {
    const Session now = record.Current();
    const PairState& a = now.pairs[0];
    const int i = now.settings.max_iterations;
    if (i > 0 &&
        (a.reason != std::to_string(i) || static_cast<int>(a.brush->pixels.size()) != i % 50))
      ++torn;
    std::string reason;
    if (record.Rejected("a", &reason) && std::stoi(reason) % 2 == 0) ++torn;
    ++reads;
  }
  editor.join();
  EXPECT_EQ(torn, 0) << "of " << reads << " reads";
  EXPECT_EQ(record.Current().settings.max_iterations, 2000);
}

// The job reads the user's word from its record at each step: an edit made there (as the
// workbench makes it, from another thread) is in the next solve, and its undo too, with no copy
// into the job.
TEST(SessionRecord, TheJobSolvesWithWhatTheRecordSaysNow) {
  const auto dir = test::TempDir("session_record_job");
  const Dataset dataset = test::CompletionMattersScene(dir / "set");
  CalibrationJob job(dataset, {});
  job.DetectAll();
  const std::string first = dataset.pairs[0].id;
  ASSERT_EQ(job.Solve().pairs[0].status, PairStatus::kAccepted);

  std::thread ui([&] {
    job.record().Edit([&](Session* s) {
      s->pairs[0].status = PairStatus::kRejected;
      s->pairs[0].reason = "the board is half in shadow";
      s->settings.huber_delta = 0.5;
    });
  });
  ui.join();
  EXPECT_EQ(job.options().advise.pipeline.solver.huber_delta, 0.5);
  const CalibrationOutcome rejected = job.Solve();
  EXPECT_EQ(rejected.pairs[0].status, PairStatus::kRejected);
  EXPECT_EQ(rejected.pairs[0].reason, "the board is half in shadow");
  const Session written = job.ToSession(dataset.manifest);
  EXPECT_EQ(written.pairs[0].reason, "the board is half in shadow");
  EXPECT_EQ(written.settings.huber_delta, 0.5);

  // The job's own word (the command line's) is an undo step in the same record.
  job.SetRejected(dataset.pairs[1].id, true);
  EXPECT_EQ(job.Solve().pairs[1].status, PairStatus::kRejected);
  ASSERT_TRUE(job.record().Undo());
  EXPECT_EQ(job.Solve().pairs[1].status, PairStatus::kAccepted);
  ASSERT_TRUE(job.record().Undo());
  const CalibrationOutcome& back = job.Solve();
  EXPECT_EQ(back.pairs[0].status, PairStatus::kAccepted);
  EXPECT_EQ(job.options().advise.pipeline.solver.huber_delta, PipelineOptions{}.solver.huber_delta);
  ASSERT_TRUE(back.solution) << back.failure;
}

}  // namespace
}  // namespace calibench
