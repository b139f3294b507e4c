// The open session both workbenches keep (EditedSession, ui/state/session_opening.h), without a
// window or a job: its record's edits set the undo buttons and autosave, undo and redo step
// through them and say when there is nothing, save-as locks and moves the autosave, a file that
// cannot be written is said on the status line and retried, and a session another workbench holds
// is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/session/session.h"
#include "tests/test_support.h"
#include "ui/state/session_opening.h"

namespace calibench::ui {
namespace {

// What EditedSession reads and writes of a workbench's snapshot.
struct FakeSnapshot : SnapshotHeader {
  std::filesystem::path session_path;
  std::string save_error;
  bool can_undo = false, can_redo = false;
};

// A record of two pairs and the host of one controller (its mutex, state and worker).
class EditedSessionTest : public ::testing::Test {
 protected:
  EditedSessionTest() : worker_([](const std::string&) {}) {
    Session session;
    session.dataset = dir_ / "dataset.json";
    session.pairs.resize(2);
    session.pairs[0].id = "a";
    session.pairs[1].id = "b";
    record_.Reset(session);
  }
  TaskHost<FakeSnapshot> Host() { return {mutex_, state_, worker_}; }
  void Reject(const std::string& id) {
    record_.Edit([&](Session* s) { FindPair(s, id)->status = PairStatus::kRejected; });
  }

  // A folder of each test's own.
  const std::filesystem::path dir_ =
      test::TempDir(std::string("edited_session_") +
                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
  CheckedMutex mutex_;
  FakeSnapshot state_;
  WorkQueue worker_;
  SessionRecord record_;
};

TEST_F(EditedSessionTest, EditsSetTheUndoButtonsAndAutosaveUndoAndRedoStepThroughThem) {
  EditedSession<FakeSnapshot> session(Host());
  const std::filesystem::path path = dir_ / "calibench.session.json";
  std::lock_guard lock(mutex_);
  session.Attach(&record_, path, std::nullopt);
  EXPECT_EQ(state_.session_path, path);
  EXPECT_FALSE(state_.can_undo);
  EXPECT_FALSE(state_.can_redo);

  Reject("a");
  const std::uint64_t before = state_.generation;
  session.Edited();
  EXPECT_TRUE(state_.can_undo);
  EXPECT_FALSE(state_.can_redo);
  EXPECT_GT(state_.generation, before);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_EQ(LoadSession(path).pairs[0].status, PairStatus::kRejected);

  const std::optional<Session> undone = session.Step(/*undo=*/true);
  ASSERT_TRUE(undone);
  EXPECT_NE(undone->pairs[0].status, PairStatus::kRejected);
  EXPECT_FALSE(state_.can_undo);
  EXPECT_TRUE(state_.can_redo);
  // Nothing further back: none, and the line says so.
  EXPECT_FALSE(session.Step(/*undo=*/true));
  EXPECT_EQ(state_.status_line, "nothing to undo");
  EXPECT_FALSE(state_.status_is_error);

  const std::optional<Session> redone = session.Step(/*undo=*/false);
  ASSERT_TRUE(redone);
  EXPECT_EQ(redone->pairs[0].status, PairStatus::kRejected);
  EXPECT_TRUE(state_.can_undo);
  EXPECT_FALSE(state_.can_redo);
  EXPECT_FALSE(session.Step(/*undo=*/false));
  EXPECT_EQ(state_.status_line, "nothing to redo");
}

TEST_F(EditedSessionTest, SaveAsWritesTheRecordThereAndAutosavesThereFromThenOn) {
  EditedSession<FakeSnapshot> session(Host());
  std::lock_guard lock(mutex_);
  session.Attach(&record_, dir_ / "first.session.json", std::nullopt);
  const std::filesystem::path copy = dir_ / "copy.session.json";
  session.SaveAs(copy);
  EXPECT_EQ(state_.session_path, copy);
  EXPECT_TRUE(state_.save_error.empty());
  EXPECT_EQ(state_.status_line, "saved session " + copy.string());
  Reject("b");
  session.Edited();
  EXPECT_EQ(LoadSession(copy).pairs[1].status, PairStatus::kRejected);
  // The copy is this workbench's now: another one may not open it for editing.
  std::string note;
  EXPECT_THROW(LockSessionFile(copy, std::nullopt, &note), IoError);
  // Its own lock it keeps (no second lock of the same file).
  EXPECT_FALSE(session.Lock(copy, &note));
}

TEST_F(EditedSessionTest, AnAutosaveThatFailsIsSaidAndRetriedAtTheNextEdit) {
  EditedSession<FakeSnapshot> session(Host());
  // The session's folder is a file: nothing can be written under it.
  const std::filesystem::path blocker = dir_ / "not_a_folder";
  std::ofstream(blocker) << "x";
  std::lock_guard lock(mutex_);
  session.Attach(&record_, blocker / "calibench.session.json", std::nullopt);
  Reject("a");
  session.Edited();
  EXPECT_TRUE(state_.status_is_error);
  EXPECT_NE(state_.status_line.find("autosave failed"), std::string::npos) << state_.status_line;
  EXPECT_NE(state_.save_error.find("not_a_folder"), std::string::npos) << state_.save_error;
  // Nothing was lost: the record keeps the edit, and once the folder can hold the file the next
  // edit writes it.
  std::filesystem::remove(blocker);
  std::filesystem::create_directories(blocker);
  Reject("b");
  session.Edited();
  EXPECT_TRUE(state_.save_error.empty());
  const Session saved = LoadSession(blocker / "calibench.session.json");
  EXPECT_EQ(saved.pairs[0].status, PairStatus::kRejected);
  EXPECT_EQ(saved.pairs[1].status, PairStatus::kRejected);
}

TEST_F(EditedSessionTest, WithoutARecordNothingIsSavedAndSaveAsSaysWhy) {
  EditedSession<FakeSnapshot> session(Host());
  std::lock_guard lock(mutex_);
  EXPECT_FALSE(session.Step(/*undo=*/true));
  session.SaveAs(dir_ / "nothing.session.json");
  EXPECT_TRUE(state_.status_is_error);
  EXPECT_NE(state_.save_error.find("open a dataset first"), std::string::npos) << state_.save_error;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "nothing.session.json"));
}

}  // namespace
}  // namespace calibench::ui
