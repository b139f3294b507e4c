// The session file: exact round trips, dataset path handling, rejection of broken files without
// touching them, atomic saves, undo/redo and the autosaver.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "core/session/session.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

BrushMask Mask(int rows, int columns, std::vector<int> pixels) {
  BrushMask mask;
  mask.rows = rows;
  mask.columns = columns;
  mask.pixels = std::move(pixels);
  return mask;
}

// Every field away from its default, doubles that only survive with full precision.
Session FullSession(const fs::path& dataset) {
  Session s;
  s.dataset = dataset;
  const PairStatus statuses[] = {PairStatus::kPending, PairStatus::kAccepted, PairStatus::kRejected,
                                 PairStatus::kFailed};
  for (int i = 0; i < 4; ++i) {
    PairState p;
    p.id = "000" + std::to_string(i);
    p.status = statuses[i];
    s.pairs.push_back(p);
  }
  s.pairs[1].brush = Mask(64, 1024, {5, 6, 7, 1029, 1030, 1031, 1032, 4000, 65535});
  s.pairs[2].reason = "board half outside the image";
  s.pairs[2].brush = Mask(16, 900, {0});
  s.pairs[2].brush_from_seed = true;
  s.pairs[3].reason = "clouds/0003.pcd: cannot open \"file\"\n(second line)";
  s.pairs[3].brush = Mask(32, 512, {});
  s.settings.huber_delta = 1.0 / 3.0;
  s.settings.max_iterations = 17;
  s.settings.ransac_threshold_m = 0.1 + 0.2;
  // The workbench's view, kept as it is (ui/state/view_state.h reads it); members sorted, as a
  // reread file gives them.
  s.view_json = R"({"orbit_target_m":[0.1,-5e-324,7.0],"point_opacity":0.7,)"
                R"("selected_pair":"0002","visibility":"zbuffer"})";
  SessionResult r;
  r.cam_from_lidar.linear() =
      Eigen::AngleAxisd(0.3, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  r.cam_from_lidar.translation() = Vec3(0.1, -0.07, 0.2 / 3.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) r.covariance(i, j) = normal(rng) * 1e-5;
  r.iterations = 9;
  r.converged = true;
  for (int i = 0; i < 200; ++i) r.cost_history.push_back(std::exp(normal(rng) * 20.0));
  r.cost_history.push_back(std::numeric_limits<double>::infinity());
  r.weak_directions = {"translation along camera x", "rotation about camera z"};
  r.well_constrained = false;
  for (int i = 0; i < 4; ++i) {
    r.step_history.push_back(std::pow(10.0, -3 * i) / 3.0);
    Pose estimate = r.cam_from_lidar;
    estimate.translation().x() += 0.01 / (i + 1);
    r.estimate_history.push_back(estimate);
  }
  r.range_offset = RangeOffsetEstimate{-0.0234, 0.0012, Vec3(-0.07, 0.07, 0.72), true};
  r.unmodelled_range_offset = RangeOffsetEstimate{-0.0218, 0.0056, Vec3(0.1, -0.2, 1.0 / 3), true};
  r.num_edge_residuals = 671;
  r.edge_dilation = EdgeDilationEstimate{0.0067, 0.0003, 0.002};
  r.covariance_inflation = 11.2;
  r.plane_variance_factor = 30.0 / 7;
  r.edge_variance_factor = 1.85;
  r.termination = {TerminationTest::kIterationCap, 3.0 / 7 * 1e-5, 1e-6, 100};
  r.notes = {"LiDAR model: spinning for all 3 pairs (the cloud carries rings)", "edges: none"};
  r.targetless_provenance = "estimated without a target by the workbench's check, around \"R\"";
  s.result = r;
  return s;
}

// Loading `text` must fail with an IoError naming the file and containing `problem`, and must
// leave the file byte-for-byte as it was, with no temporary beside it.
void ExpectRejected(const fs::path& dir, const std::string& text, const std::string& problem) {
  const fs::path path = dir / "broken.session.json";
  WriteBytes(path, text);
  try {
    LoadSession(path);
    ADD_FAILURE() << "loaded a broken session; expected: " << problem;
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }
  EXPECT_EQ(test::ReadFileBytes(path), text);
  EXPECT_TRUE(test::TemporariesBeside(path).empty());
}

// The saved text with `from` replaced by `to` once (a hand-edited or damaged file).
std::string Edit(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(SessionTest, FullyPopulatedSessionRoundTripsExactly) {
  const fs::path dir = test::TempDir("session_round_trip");
  const Session s = FullSession(dir / "data" / "dataset.json");
  const fs::path path = dir / "calibench.session.json";
  const std::string text = SessionToJson(s, path);
  EXPECT_EQ(SessionFromJson(text, path), s);
  SaveSession(path, s);
  const Session loaded = LoadSession(path);
  EXPECT_EQ(loaded, s);
  EXPECT_EQ(SessionToJson(loaded, path), text);  // a second save changes nothing
  EXPECT_EQ(loaded.pairs[1].brush->pixels, s.pairs[1].brush->pixels);
  EXPECT_TRUE(std::isinf(loaded.result->cost_history.back()));

  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_EQ(json["format"], "calibench.session.v1");
  EXPECT_EQ(json["version"], 1);
  EXPECT_EQ(json["pairs"][3]["status"], "failed");
  EXPECT_EQ(json["view"]["visibility"], "zbuffer");
  EXPECT_TRUE(json["result"]["cam_from_lidar"].contains("matrix"));
  EXPECT_NE(json["result"]["direction"].get<std::string>().find("x_in_cam = cam_from_lidar"),
            std::string::npos);
  // Runs of consecutive pixels: {5,6,7} {1029..1032} {4000} {65535}.
  EXPECT_EQ(json["pairs"][1]["brush"]["pixel_runs"].size(), 4u);
  EXPECT_EQ(text.find("\"format\""), text.find('"'));  // format is the first key
}

TEST(SessionTest, NonFiniteNumbersLoadBack) {
  Session s = FullSession("/data/dataset.json");
  s.result->covariance(2, 3) = -std::numeric_limits<double>::infinity();
  const Session loaded = SessionFromJson(SessionToJson(s, "/x/s.json"), "/x/s.json");
  EXPECT_EQ(loaded.result->covariance(2, 3), -std::numeric_limits<double>::infinity());
}

TEST(SessionTest, InvalidUtf8InAReasonIsReplacedNotFatal) {
  Session s = FullSession("/data/dataset.json");
  s.pairs[3].reason = "cannot open caf\xe9.pcd";  // Latin-1 bytes from a file name
  const Session loaded = SessionFromJson(SessionToJson(s), "/x/s.json");
  EXPECT_EQ(loaded.pairs[3].reason.substr(0, 15), "cannot open caf");
}

TEST(SessionTest, SessionWithoutResultOrBrushRoundTrips) {
  Session s;
  s.dataset = "/somewhere/dataset.json";
  s.pairs.resize(2);
  s.pairs[0].id = "a";
  s.pairs[1].id = "b";
  const std::string text = SessionToJson(s);
  EXPECT_EQ(nlohmann::json::parse(text)["dataset"], "/somewhere/dataset.json");
  EXPECT_EQ(SessionFromJson(text, "/elsewhere/s.json"), s);
}

TEST(SessionTest, DatasetPathIsRelativeInsideTheSessionTreeAbsoluteOutside) {
  const fs::path dir = test::TempDir("session_paths");
  const fs::path inside = dir / "recording" / "dataset.json";
  const fs::path session_path = dir / "calibench.session.json";
  const std::string text = SessionToJson(FullSession(inside), session_path);
  EXPECT_EQ(nlohmann::json::parse(text)["dataset"], "recording/dataset.json");
  // Moving the whole tree moves the dataset with it.
  const fs::path moved = test::TempDir("session_paths_moved");
  EXPECT_EQ(SessionFromJson(text, moved / "calibench.session.json").dataset,
            moved / "recording" / "dataset.json");

  const fs::path outside = "/mnt/recordings/day1/dataset.json";
  const std::string text_outside = SessionToJson(FullSession(outside), session_path);
  EXPECT_EQ(nlohmann::json::parse(text_outside)["dataset"], outside.string());
  EXPECT_EQ(SessionFromJson(text_outside, moved / "s.json").dataset, outside);
  // A sibling folder is outside the session's tree: absolute, not "../".
  const fs::path sibling = dir.parent_path() / "other" / "dataset.json";
  EXPECT_EQ(nlohmann::json::parse(SessionToJson(FullSession(sibling), session_path))["dataset"],
            sibling.string());

  // The shorthand form names a folder; the session may sit inside it.
  Session folder = FullSession(dir);
  const std::string folder_text = SessionToJson(folder, session_path);
  EXPECT_EQ(nlohmann::json::parse(folder_text)["dataset"], ".");
  EXPECT_EQ(SessionFromJson(folder_text, session_path), folder);
}

TEST(SessionTest, NewSessionHasOnePendingPairPerDatasetPair) {
  Dataset dataset;
  dataset.manifest = "recording/./sub/../dataset.json";
  for (const char* id : {"0000", "0001", "0007"}) {
    PairEntry entry;
    entry.id = id;
    entry.lidar_seed = LidarSeed{Vec3(4, 0, 0), 0.2};
    dataset.pairs.push_back(entry);
  }
  const Session s = NewSession(dataset);
  EXPECT_EQ(s.version, 1);
  EXPECT_EQ(s.dataset, fs::current_path() / "recording" / "dataset.json");
  ASSERT_EQ(s.pairs.size(), 3u);
  EXPECT_EQ(s.pairs[2].id, "0007");
  for (const PairState& p : s.pairs) {
    EXPECT_EQ(p.status, PairStatus::kPending);
    EXPECT_TRUE(p.reason.empty());
    EXPECT_FALSE(p.brush.has_value());
    EXPECT_FALSE(p.brush_from_seed);
  }
  EXPECT_EQ(s.view_json, "{}");  // the workbench selects the first pair
  EXPECT_FALSE(s.result.has_value());
  EXPECT_EQ(s.settings.huber_delta, SolverOptions{}.huber_delta);
  EXPECT_EQ(s.settings.max_iterations, SolverOptions{}.max_iterations);
  EXPECT_EQ(s.settings.ransac_threshold_m, LidarPlaneOptions{}.ransac_threshold_m);

  PipelineOptions options;
  Session edited = s;
  edited.settings.huber_delta = 0.05;
  edited.settings.max_iterations = 7;
  edited.settings.ransac_threshold_m = 0.02;
  edited.settings.Apply(&options);
  EXPECT_EQ(options.solver.huber_delta, 0.05);
  EXPECT_EQ(options.solver.max_iterations, 7);
  EXPECT_EQ(options.lidar_plane.ransac_threshold_m, 0.02);
}

TEST(SessionTest, BrokenFilesAreRejectedAndLeftUntouched) {
  const fs::path dir = test::TempDir("session_broken");
  const std::string good = SessionToJson(FullSession(dir / "dataset.json"), dir / "s.json");
  ExpectRejected(dir, "{ this is not json", "corrupt or truncated JSON");
  ExpectRejected(dir, good.substr(0, good.size() / 2), "corrupt or truncated JSON");
  ExpectRejected(dir, "", "corrupt or truncated JSON");
  ExpectRejected(dir, "[1, 2]", "not a Calibench session");
  ExpectRejected(dir, Edit(good, "calibench.session.v1", "calibench.result.v1"),
                 "not a Calibench session");
  ExpectRejected(dir, Edit(good, "\"format\": \"calibench.session.v1\",", ""), "format is missing");
  ExpectRejected(dir, Edit(good, "\"version\": 1", "\"version\": 2"), "session version 2");
  ExpectRejected(dir,
                 Edit(good, "\"max_iterations\": 17", "\"max_iterations\": 18446744073709551615"),
                 "options.max_iterations: must be an integer");
  ExpectRejected(dir, Edit(good, "\"status\": \"accepted\"", "\"status\": \"maybe\""),
                 "pairs[1].status: unknown value \"maybe\"");
  ExpectRejected(dir, Edit(good, "\"id\": \"0001\"", "\"id\": \"0000\""), "appears twice");
  ExpectRejected(dir, Edit(good, "\"max_iterations\": 17", "\"max_iterations\": \"17\""),
                 "options.max_iterations: must be an integer");
  nlohmann::json view_not_an_object = nlohmann::json::parse(good);
  view_not_an_object["view"] = 5;
  ExpectRejected(dir, view_not_an_object.dump(), "view: must be a JSON object");
  ExpectRejected(dir, Edit(good, "\"reason\": \"board half outside the image\",", ""),
                 "pairs[2].reason: missing");
}

TEST(SessionTest, BrushMasksOutsideTheirImageOrUnsortedAreRejected) {
  const fs::path dir = test::TempDir("session_brush");
  Session s = FullSession(dir / "dataset.json");
  s.pairs[2].brush = Mask(2, 3, {4, 5});  // the last pixel of a 2x3 image is 5
  const std::string good = SessionToJson(s, dir / "s.json");
  ASSERT_NO_THROW(SessionFromJson(good, dir / "s.json"));
  const nlohmann::json brush = nlohmann::json::parse(good)["pairs"][2]["brush"];
  ASSERT_EQ(brush["pixel_runs"], nlohmann::json::parse("[[4, 2]]"));
  const auto with_runs = [&](const char* runs) {
    nlohmann::ordered_json json = nlohmann::ordered_json::parse(good);
    json["pairs"][2]["brush"]["pixel_runs"] = nlohmann::ordered_json::parse(runs);
    return json.dump(2);
  };
  ExpectRejected(dir, with_runs("[[4, 3]]"),
                 "pairs[2].brush.pixel_runs[0]: pixels 4..6 lie outside the 2x3 LiDAR image");
  ExpectRejected(dir, with_runs("[[-1, 1]]"), "pairs[2].brush.pixel_runs[0]");
  ExpectRejected(dir, with_runs("[[4, 1], [2, 1]]"), "sorted and must not overlap");
  ExpectRejected(dir, with_runs("[[1, 2], [2, 1]]"), "sorted and must not overlap");
  ExpectRejected(dir, with_runs("[[1, 0]]"), "count must be at least 1");
  ExpectRejected(dir, with_runs("[[1, 2, 3]]"), "[start, count]");
  ExpectRejected(dir, Edit(good, "\"image_rows\": 2", "\"image_rows\": 0"), "at least 1");
  ExpectRejected(dir, Edit(good, "\"image_rows\": 2", "\"image_rows\": 100000000"),
                 "image too large");
}

TEST(SessionTest, SavingABrokenMaskIsAProgrammerError) {
  Session s = FullSession("/d/dataset.json");
  s.pairs[0].brush = Mask(2, 3, {3, 1});  // unsorted: would save a file that cannot load
  EXPECT_THROW(SessionToJson(s), std::logic_error);
  s.pairs[0].brush = Mask(2, 3, {6});
  EXPECT_THROW(SessionToJson(s), std::logic_error);
}

TEST(SessionTest, BrushFromAnotherLidarImageLayoutIsRefused) {
  const BrushMask mask = Mask(64, 1800, {10, 11});
  std::string why;
  EXPECT_TRUE(BrushFitsImage(mask, 64, 1800, &why));
  EXPECT_FALSE(BrushFitsImage(mask, 64, 2048, &why));
  EXPECT_NE(why.find("64x1800"), std::string::npos) << why;
  EXPECT_NE(why.find("64x2048"), std::string::npos) << why;
}

TEST(SessionTest, SaveIsAtomicAndReplacesAnExistingFile) {
  const fs::path dir = test::TempDir("session_save");
  const fs::path path = dir / "calibench.session.json";
  Session s = FullSession(dir / "dataset.json");
  SaveSession(path, s);
  EXPECT_EQ(LoadSession(path), s);
  s.pairs[0].status = PairStatus::kRejected;
  s.pairs[0].reason = "blurred";
  SaveSession(path, s);
  EXPECT_EQ(LoadSession(path), s);
  EXPECT_EQ(test::ReadFileBytes(path), SessionToJson(s, path));
  EXPECT_TRUE(test::TemporariesBeside(path).empty());
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1);
  EXPECT_THROW(SaveSession(dir / "missing" / "s.json", s), IoError);
  EXPECT_THROW(LoadSession(dir / "missing.json"), IoError);
}

TEST(SessionTest, UndoRedoWalksTheEditHistory) {
  std::vector<Session> states(5, FullSession("/d/dataset.json"));
  for (int i = 0; i < 5; ++i) states[i].settings.max_iterations = 10 + i % 4;
  states[4].pairs[0].status = PairStatus::kAccepted;
  SessionHistory history;
  EXPECT_FALSE(history.CanUndo());
  EXPECT_FALSE(history.Undo().has_value());
  history.Push(states[0]);  // the opened state: nothing to undo yet
  EXPECT_FALSE(history.CanUndo());
  history.Push(states[1]);
  history.Push(states[2]);
  history.Push(states[2]);  // no change, no undo step
  EXPECT_EQ(history.UndoDepth(), 2u);
  EXPECT_EQ(history.Undo(), states[1]);
  EXPECT_EQ(history.Undo(), states[0]);
  EXPECT_FALSE(history.CanUndo());
  EXPECT_FALSE(history.Undo().has_value());
  EXPECT_TRUE(history.CanRedo());
  EXPECT_EQ(history.Redo(), states[1]);
  EXPECT_EQ(history.Redo(), states[2]);
  EXPECT_FALSE(history.CanRedo());
  EXPECT_FALSE(history.Redo().has_value());
  EXPECT_EQ(history.Undo(), states[1]);
  history.Push(states[4]);  // a new edit drops the redo branch
  EXPECT_FALSE(history.CanRedo());
  EXPECT_EQ(history.Undo(), states[1]);
  EXPECT_EQ(history.Undo(), states[0]);
  history.Reset(states[3]);
  EXPECT_FALSE(history.CanUndo());
  EXPECT_FALSE(history.CanRedo());
}

TEST(SessionTest, HistoryKeepsABoundedNumberOfSteps) {
  SessionHistory history(3);
  Session s = FullSession("/d/dataset.json");
  for (int i = 0; i < 10; ++i) {
    s.settings.max_iterations = 10 + i;
    history.Push(s);
  }
  EXPECT_EQ(history.UndoDepth(), 3u);
  std::optional<Session> restored;
  for (int i = 0; i < 3; ++i) restored = history.Undo();
  EXPECT_EQ(restored->settings.max_iterations, 16);
  EXPECT_FALSE(history.CanUndo());
}

TEST(SessionTest, AutosaverWritesOnlyWhenTheSessionChanged) {
  const fs::path dir = test::TempDir("session_autosave");
  const fs::path path = dir / "autosave.session.json";
  Autosaver saver(path);
  Session s = FullSession(dir / "dataset.json");
  EXPECT_TRUE(saver.Save(s));
  EXPECT_EQ(saver.writes(), 1);
  // Back-date the file: an identical save must not touch it.
  const auto old_time = fs::last_write_time(path) - std::chrono::hours(1);
  fs::last_write_time(path, old_time);
  for (int i = 0; i < 20; ++i) EXPECT_FALSE(saver.Save(s));
  EXPECT_EQ(saver.writes(), 1);
  EXPECT_EQ(fs::last_write_time(path), old_time);
  s.settings.max_iterations += 1;
  EXPECT_TRUE(saver.Save(s));
  EXPECT_EQ(saver.writes(), 2);
  EXPECT_NE(fs::last_write_time(path), old_time);
  EXPECT_EQ(LoadSession(path), s);
  EXPECT_TRUE(test::TemporariesBeside(path).empty());

  Autosaver failing(dir / "missing" / "s.json");
  EXPECT_THROW(failing.Save(s), IoError);
  EXPECT_EQ(failing.writes(), 0);
  fs::create_directories(dir / "missing");
  EXPECT_TRUE(failing.Save(s));  // retried after the failure, not skipped as unchanged
}

TEST(SessionTest, AutosaverKeepsTheLastVersionsAsRotatingBackups) {
  const fs::path dir = test::TempDir("session_backups");
  const fs::path path = dir / "calibench.session.json";
  EXPECT_EQ(SessionBackupPath(path, 2), dir / "calibench.session.backup-2.json");
  AutosaveOptions every_save;
  every_save.backups = 3;
  every_save.backup_interval_s = 0.0;
  Autosaver saver(path, every_save);
  Session s = FullSession(dir / "dataset.json");
  for (int version = 1; version <= 6; ++version) {
    s.settings.max_iterations = version;
    ASSERT_TRUE(saver.Save(s));
  }
  EXPECT_EQ(LoadSession(path).settings.max_iterations, 6);
  for (int n = 1; n <= 3; ++n)
    EXPECT_EQ(LoadSession(SessionBackupPath(path, n)).settings.max_iterations, 6 - n) << n;
  EXPECT_FALSE(fs::exists(SessionBackupPath(path, 4)));

  // By default the first save of a process keeps the file as it found it; later saves within the
  // interval do not push it out.
  Autosaver reopened(path);
  for (int version = 7; version <= 9; ++version) {
    s.settings.max_iterations = version;
    ASSERT_TRUE(reopened.Save(s));
  }
  EXPECT_EQ(LoadSession(SessionBackupPath(path, 1)).settings.max_iterations, 6);
  EXPECT_EQ(LoadSession(SessionBackupPath(path, 2)).settings.max_iterations, 5);

  AutosaveOptions bad;
  bad.backups = -1;
  EXPECT_THROW(Autosaver(path, bad), std::invalid_argument);
}

// A child process autosaves in a loop (a backup at every save) and is killed with SIGKILL at 200
// random moments: every time the session and its newest backup load whole, and the temporary a
// kill can leave (only in the instant between naming it and the rename) is gone once the next
// autosaver starts.
TEST(SessionTest, AutosaveSurvivesSigkillAtAnyMoment) {
  const fs::path dir = test::TempDir("session_sigkill");
  const fs::path path = dir / "calibench.session.json";
  AutosaveOptions every_save;
  every_save.backups = 3;
  every_save.backup_interval_s = 0.0;
  const Session base = FullSession(dir / "dataset.json");
  SaveSession(path, base);
  std::mt19937 random(7);
  std::uniform_int_distribution<int> delay_us(0, 4000);
  int named_temporaries_left = 0;
  for (int kill = 0; kill < 200; ++kill) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      Autosaver saver(path, every_save);
      Session s = base;
      for (int version = 1;; ++version) {
        s.settings.max_iterations = kill * 100000 + version;
        saver.Save(s);
      }
    }
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(random)));
    ::kill(child, SIGKILL);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));

    for (const fs::path& file : {path, SessionBackupPath(path, 1)}) {
      if (file != path && !fs::exists(file)) continue;
      Session loaded;
      ASSERT_NO_THROW(loaded = LoadSession(file)) << "kill " << kill << ": " << file;
      loaded.settings.max_iterations = base.settings.max_iterations;
      EXPECT_EQ(loaded, base) << "kill " << kill << ": " << file;
    }
    named_temporaries_left += static_cast<int>(test::TemporariesBeside(path).size());
    Autosaver next(path, every_save);  // the next start clears what a kill left
    ASSERT_TRUE(test::TemporariesBeside(path).empty()) << "kill " << kill;
  }
  std::printf("named temporaries left by 200 kills: %d\n", named_temporaries_left);
}

TEST(SessionTest, ResultIsTakenFromTheSolver) {
  SolverResult solver;
  solver.cam_from_lidar.translation() = Vec3(1, 2, 3);
  solver.covariance = Mat6::Identity() * 1e-6;
  solver.converged = true;
  solver.iterations = 4;
  solver.cost_history = {3.0, 1.0, 0.5};
  solver.observability.weak_directions = {"rotation about camera z"};
  solver.observability.well_constrained = false;
  const SessionResult r = SessionResultFromSolver(solver);
  EXPECT_EQ(r.cam_from_lidar.matrix(), solver.cam_from_lidar.matrix());
  EXPECT_EQ(r.covariance, solver.covariance);
  EXPECT_EQ(r.iterations, 4);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.cost_history, solver.cost_history);
  EXPECT_EQ(r.weak_directions, solver.observability.weak_directions);
  EXPECT_FALSE(r.well_constrained);
}

// A capture that grew since its session was saved is still that session's dataset: the saved
// pairs keep their state, the new ones join pending; a pair gone or reordered is another dataset.
TEST(SessionTest, ASessionReopensOverItsCaptureGrownButNotOverAnotherDataset) {
  Dataset dataset;
  dataset.manifest = "/data/capture";
  for (const char* id : {"pose1", "pose2", "pose3", "pose4"}) {
    PairEntry entry;
    entry.id = id;
    dataset.pairs.push_back(entry);
  }
  Session saved;
  saved.dataset = "/data/capture";
  saved.pairs.resize(2);
  saved.pairs[0].id = "pose1";
  saved.pairs[1].id = "pose3";
  saved.pairs[1].status = PairStatus::kRejected;
  saved.pairs[1].reason = kRejectedByUser;
  const Session grown = SessionOverDataset(saved, dataset, "/data/capture/s.json");
  ASSERT_EQ(grown.pairs.size(), 4u);
  EXPECT_EQ(grown.pairs[1].id, "pose2");
  EXPECT_EQ(grown.pairs[1].status, PairStatus::kPending);
  EXPECT_EQ(grown.pairs[2], saved.pairs[1]);

  Session reordered = saved;
  std::swap(reordered.pairs[0], reordered.pairs[1]);
  try {
    SessionOverDataset(reordered, dataset, "/data/capture/s.json");
    FAIL() << "a session whose pairs come in another order opened";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("'pose1' comes before 'pose3'"), std::string::npos)
        << e.what();
  }
  Session gone = saved;
  gone.pairs[1].id = "pose9";
  try {
    SessionOverDataset(gone, dataset, "/data/capture/s.json");
    FAIL() << "a session with a pair the dataset lacks opened";
  } catch (const IoError& e) {
    EXPECT_NE(
        std::string(e.what()).find("/data/capture/s.json: the session's pair 'pose9' is not in"),
        std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace calibench
