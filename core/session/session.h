// The workbench's editable state as plain data and a file (calibench.session.v1): per-pair
// status and brush masks, solver options, the last solve, and what the views showed (opaque here:
// the workbench's); undo/redo history and an autosaver. Reopening a saved session restores
// exactly what was on screen.
#pragma once

#include <array>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/base/file_lock.h"
#include "core/base/types.h"
#include "core/io/dataset.h"
#include "core/lidar/colormap.h"
#include "core/lidar_camera/pipeline.h"
#include "core/lidar_camera/solver.h"
#include "core/results/pair_status.h"

namespace calibench {

struct RigFolder;  // core/io/rig_folder.h

// The board region the user brushed on one pair's LiDAR image (projection by ID, lidar_image.h).
struct BrushMask {
  // Layout of the LiDAR image it was painted on (rings x azimuth bins). A mask only applies to
  // an image of the same layout; BrushFitsImage says why not.
  int rows = 0;
  int columns = 0;
  std::vector<int> pixels;  // sorted, unique pixel indices row * columns + col

  bool operator==(const BrushMask&) const = default;
};

// False (with *why naming both layouts) when the mask was painted on another image layout.
bool BrushFitsImage(const BrushMask& mask, int rows, int columns, std::string* why);

struct PairState : PairStanding {
  std::optional<BrushMask> brush;
  bool brush_from_seed = false;  // brush generated from the manifest's lidar_seed, not painted

  bool operator==(const PairState&) const = default;
};

// The part of a SolverResult the session keeps. Per-pair residuals and weights are not kept: they
// follow from the pairs' planes at cam_from_lidar.
struct SessionResult {
  Pose cam_from_lidar = Pose::Identity();  // x_in_cam = cam_from_lidar * x_in_lidar
  Mat6 covariance = Mat6::Zero();          // right perturbation, [rho (m); phi (rad)]
  int iterations = 0;
  bool converged = false;
  std::vector<double> cost_history;  // Eq. (14) cost per iteration, the initial cost first
  std::vector<std::string> weak_directions;
  bool well_constrained = false;
  // Per iteration (same length as cost_history when recorded): |delta| and the estimate, so that
  // a reopened session shows and replays the same convergence. May be empty.
  std::vector<double> step_history;
  std::vector<Pose> estimate_history;
  std::vector<int> reweighted_iterations;  // where the weights changed (IterationReport)
  // What the solve said beyond the pose (optional in the file): the range offset when estimated,
  // the board edges used, the edge dilation and how far the pairs' spread widened the covariance.
  std::optional<RangeOffsetEstimate> range_offset;
  std::optional<RangeOffsetEstimate> unmodelled_range_offset;  // SolverResult's
  int num_edge_residuals = 0;
  std::optional<EdgeDilationEstimate> edge_dilation;
  double covariance_inflation = 1.0;
  double plane_variance_factor = 1.0;
  double edge_variance_factor = 1.0;
  Termination termination;  // which test ended the solve (optional in the file)
  // The summary's words on the solve's inputs (the LiDAR model, the residuals available), as the
  // workbench showed them (optional in the file).
  std::vector<std::string> notes;
  // Not a board solve: a targetless check's estimate the user adopted (the workbench's check
  // window), and the words of where it came from; empty for a solve. An export writes it as a
  // targetless result (core/targetless/check_output.h).
  std::string targetless_provenance;

  // Exact value comparison (no tolerance), so a file round trip can be checked with ==.
  bool operator==(const SessionResult& other) const;
};
SessionResult SessionResultFromSolver(const SolverResult& solver);
// The reverse, for a reopened session: what the file keeps of a solve (no per-pair residuals,
// no observability eigenvalues); `method` is the session's solver method.
SolverResult SolverResultFromSession(const SessionResult& session, SolverMethod method);

// The settings a calibration job runs with and a session file keeps (its "options"): the session,
// the job's record and the workbench's snapshot each hold them as one field, and what they make of
// the pipeline's options is Apply's alone (docs/architecture.md, "One state").
struct JobSettings {
  SolverMethod method = SolverOptions{}.method;
  double huber_delta = SolverOptions{}.huber_delta;     // Huber threshold (see SolverOptions)
  int max_iterations = SolverOptions{}.max_iterations;  // Gauss-Newton iterations
  // A LiDAR range offset, as the user asked for it: kept across methods (the workbench's checkbox
  // keeps its value), estimated by the weighted method alone (Apply).
  bool estimate_range_offset = false;
  double ransac_threshold_m = LidarPlaneOptions{}.ransac_threshold_m;  // LiDAR plane inliers [m]

  // The settings of pipeline options (the command line's flags, a job's options).
  static JobSettings Of(const PipelineOptions& options);
  // `options` with these settings: the one place the range-offset rule is written.
  void Apply(PipelineOptions* options) const;
  PipelineOptions Over(PipelineOptions options) const {
    Apply(&options);
    return options;
  }
  // False with *why naming the setting when the solver would refuse it.
  bool Check(std::string* why) const;
  bool operator==(const JobSettings&) const = default;
};

// Where one setting lives in the job's settings and in the pipeline's options: Of and Apply copy
// it between them, so that a setting is named once, in its declaration (JobSettingFields).
template <typename T>
struct SettingSlot {
  T JobSettings::*setting;
  T& (*in_pipeline)(PipelineOptions&);
};
template <auto kMember>
auto& InSolver(PipelineOptions& options) {
  return options.solver.*kMember;
}
template <auto kMember>
auto& InLidarPlane(PipelineOptions& options) {
  return options.lidar_plane.*kMember;
}

// The settings' one declaration, in the order the command line's help lists them: each field's
// flag (--<flag>; a Python keyword is the flag with '_' for '-'), its key in the session file's
// "options", its input field in the workbench, the words of its help, and where it lives.
// app/pipeline_flags.cpp makes the flags of `calibrate`, `advise`, `watch`, `report` and `sweep`
// from it, session_json.cpp the file's "options", the workbench's solver panel its inputs; a
// setting added here is a flag, a key and (with a label) an input everywhere.
struct JobSettingField {
  std::string_view flag;
  std::string_view file_key;  // empty: the flag with '_' for '-' (Key)
  std::string_view label;     // the workbench's input; empty: drawn by a widget of its own
  std::string_view words;
  // Sessions written before the setting existed lack it: the default applies. Else required.
  bool optional_in_file = false;
  std::variant<SettingSlot<SolverMethod>, SettingSlot<double>, SettingSlot<int>, SettingSlot<bool>>
      slot;
  std::string Key() const;
};
const std::vector<JobSettingField>& JobSettingFields();

struct Session {
  int version = 1;  // of the file format; this build reads and writes 1
  // The manifest (or shorthand folder); absolute and lexically normal in memory.
  std::filesystem::path dataset;
  // The camera of a rig this session edits (Dataset::camera_name; the file's "camera", written
  // only for a rig): `dataset` is then the rig's folder or manifest. Empty for one camera.
  std::string camera;
  std::vector<PairState> pairs;  // in the dataset's order
  JobSettings settings;          // the file's "options"
  // A 2D LRF session (the LRF workbench's, `calibench lrf-calibrate --session`): the LRF method's
  // name ("refined", "paper-linear"; the file's "options"."lrf_method"), `dataset` an LRF manifest
  // and `result` the last LRF solve (cam_from_lidar holding cam_from_lrf). Empty for a LiDAR-camera
  // session, whose solver settings above are then the ones that apply.
  std::string lrf_method;
  // What the workbench's views showed (ui/state/view_state.h reads and writes it): the file's
  // "view" object as JSON text, which core keeps as it is and never reads.
  std::string view_json = "{}";
  std::optional<SessionResult> result;  // the last solve, if any

  bool operator==(const Session&) const = default;
};

// The form Session::dataset is kept in: absolute (against the working directory), lexically
// normal, no trailing separator. Use it when setting Session::dataset from a user's path.
std::filesystem::path NormalizeSessionPath(const std::filesystem::path& path);

// Where the workbench keeps a dataset's session unless told: calibench.session.json in the
// dataset's folder (the manifest's folder), calibench.session.<camera>.json for a rig's camera.
std::filesystem::path DefaultSessionPath(const std::filesystem::path& dataset,
                                         const std::string& camera = "");

// One pending PairState per dataset pair, default options, an empty view (the workbench then
// selects the first pair).
Session NewSession(const Dataset& dataset);

// The user's word on one pair as the pipeline takes it: its painted brush (not one pictured from
// a seed) and its rejection.
PairEdit EditOfPair(const PairState& pair);
// The user's decisions in the session as the pipeline takes them: painted brushes (not those
// pictured from a seed) and rejections, by pair id. `calibench calibrate --session` and the
// workbench then compute the same calibration.
PairEdits EditsFromSession(const Session& session);
// The edits of a rig's cameras by camera name (`calibrate --session`, `report --session` on a rig:
// one session per camera, calibench.session.<camera>.json), each loaded as LoadSession does.
// IoError naming the session when it is not of a camera of `rig` (another dataset, or a camera the
// rig has not).
std::map<std::string, PairEdits> RigEditsOfSessions(const RigFolder& rig,
                                                    const std::vector<std::string>& session_paths);

// The session as JSON text for a file at session_path: the dataset path is written relative to
// the session file's folder when it lies under it, absolute otherwise. Doubles round-trip
// exactly; non-finite ones are written as the strings "nan", "inf", "-inf".
// An empty session_path writes the dataset path absolute. Requires a non-empty session.dataset,
// version 1, and brush masks whose pixels are sorted, unique and inside their image.
std::string SessionToJson(const Session& session, const std::filesystem::path& session_path = {});

// Parses session text read from source_path (named in errors; relative dataset paths resolve
// against its folder). Throws IoError naming source_path and the problem for invalid JSON, a
// wrong format or version, missing or mistyped fields, unknown status/mode names, duplicate
// pair ids, or brush masks that are unsorted or outside their image.
Session SessionFromJson(const std::string& text, const std::filesystem::path& source_path);

// Throws IoError naming `path` and what opens it when `session` is a 2D LRF session: what reads
// LiDAR-camera sessions calls it.
void RefuseLrfSession(const Session& session, const std::filesystem::path& path);

// Reads a session file; never writes it. Throws IoError naming the file and the problem.
Session LoadSession(const std::filesystem::path& path);
// A session with the dataset it names, checked to be that dataset's: its pairs in the same order
// (a session's edits and view are by pair; reopened on other pairs they would mislabel).
// Throws IoError naming the session, the manifest and the first difference.
// A capture that grew since the session was saved (a watched folder, a recording imported
// again) is that dataset still: the saved pairs keep their state and the new ones join as pending
// (SessionOverDataset).
struct SessionWithDataset {
  Session session;
  Dataset dataset;
};
// An LRF session (Session::lrf_method) is refused (RefuseLrfSession).
SessionWithDataset LoadSessionWithDataset(const std::filesystem::path& session_path);
// `saved` over the pairs `dataset` holds now: each saved pair keeps its state, the dataset's other
// pairs join as pending, in the dataset's order. Throws IoError naming `session_path` when a saved
// pair is missing from the dataset or the two order them differently (another dataset, or files
// removed: the session's edits would land on other pairs).
Session SessionOverDataset(Session saved, const Dataset& dataset,
                           const std::filesystem::path& session_path);
// The same over the pair ids `manifest` holds now, in its order (an LRF dataset's).
Session SessionOverPairs(Session saved, const std::vector<std::string>& ids,
                         const std::filesystem::path& manifest,
                         const std::filesystem::path& session_path);
// Whether the file is a session (its first 4 KB name calibench.session.v1): what `export`,
// `report` and the workbench's Open tell a session from a result or a manifest by. False for a
// file that cannot be read.
bool IsSessionFile(const std::filesystem::path& path);

// Locks a session file for one workbench (FileLock on <session>.lock); nullopt when `held` (the
// workbench's lock) is that file's already. Throws IoError naming the file and the holder when
// another workbench has it. A folder where no lock file can be made gets none (nullopt, *note says
// why): editing goes on there, and autosave says why it fails.
std::optional<FileLock> LockSessionFile(const std::filesystem::path& session,
                                        const std::optional<FileLock>& held, std::string* note);

// What a workbench does with the session a dataset it opens finds beside it (`path`): `load` reads
// a candidate file and checks it opens (it throws IoError when not, and keeps what it read). The
// file itself is tried, then its autosave backups newest first (SessionBackupPath); when none
// opens, or `fresh`, the file is moved aside (MoveSessionAside). Returns the file `load` last read
// successfully (empty: none, a new session starts) and, in *note, what happened in words the
// status line shows. Throws IoError when the file cannot be moved aside.
std::filesystem::path ResumeSessionBeside(
    const std::filesystem::path& path, bool fresh,
    const std::function<void(const std::filesystem::path&)>& load, std::string* note);

// Moves a session file that will not be resumed aside, to `<path>.<YYYYmmdd-HHMMSS>.bak` (a new
// name each time), and returns that name. Throws IoError naming both when the move fails (the file
// is then left as it is).
std::filesystem::path MoveSessionAside(const std::filesystem::path& path);

// Writes atomically (temporary + rename); throws IoError naming the file.
void SaveSession(const std::filesystem::path& path, const Session& session);

// Undo/redo over whole session states. Push the state after every edit that should be
// undoable; Undo/Redo return the state to restore (nullopt when there is none). The view is part
// of each state: a caller that should not undo camera moves keeps its current view on restore.
class SessionHistory {
 public:
  explicit SessionHistory(std::size_t max_depth = 100);  // undo steps kept, >= 1

  // Forgets everything; `state` becomes the current state with nothing to undo.
  void Reset(const Session& state);
  // Records the state after an edit and drops the redo branch. A state equal to the current one
  // is ignored (no empty undo steps). The first Push after construction acts as Reset.
  void Push(const Session& state);
  // Replaces the current state without a new undo step: the rest of an edit already pushed (the
  // later dabs of one brush stroke, the solve it caused) or a change that is no edit (the pair
  // selected). The redo branch stays: selecting a pair after an undo does not lose the redo.
  void Amend(const Session& state);
  std::optional<Session> Undo();
  std::optional<Session> Redo();
  bool CanUndo() const { return cursor_ > 0; }
  bool CanRedo() const { return cursor_ + 1 < states_.size(); }
  std::size_t UndoDepth() const { return cursor_; }

 private:
  std::size_t max_depth_;
  std::deque<Session> states_;  // oldest first; states_[cursor_] is the current state
  std::size_t cursor_ = 0;
};

// How many earlier versions of a session autosave keeps, and how far apart.
struct AutosaveOptions {
  // Earlier versions kept as <stem>.backup-1<ext> (newest) ... backup-<backups><ext>; 0 = none.
  int backups = 5;
  // Seconds between backups: the first save of a process backs up the file as it found it, later
  // saves only when the newest backup is at least this old, so the backups span minutes of work
  // rather than the last few dabs of one brush stroke. 0 = every save.
  double backup_interval_s = 60.0;
  bool Check(std::string* why) const;
};

// The n-th newest backup of a session file (n >= 1).
std::filesystem::path SessionBackupPath(const std::filesystem::path& session, int n);

// Saves a session to one file whenever its text changed, so it can be called after every edit.
// Writes are atomic (temporary, fsync, rename); before a write replaces the file, the file becomes
// the newest backup (a hard link, so no copy) when a backup is due.
class Autosaver {
 public:
  // Removes the temporaries that killed writers left beside `path`.
  explicit Autosaver(std::filesystem::path path, AutosaveOptions options = {});

  // Writes atomically unless the text equals the last one written; true when it wrote. Throws
  // IoError naming the file; a failed write is retried on the next call.
  bool Save(const Session& session);
  const std::filesystem::path& path() const { return path_; }
  int writes() const { return writes_; }  // files actually written

 private:
  void BackUp();

  std::filesystem::path path_;
  AutosaveOptions options_;
  std::string last_text_;
  bool has_written_ = false;
  int writes_ = 0;
  double last_backup_s_ = -1.0;  // steady-clock seconds; < 0 = none yet in this process
};

}  // namespace calibench
