// Session data helpers, file load/save, undo/redo history and the autosaver. The JSON form is in
// session_json.cpp.
#include "core/session/session.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/io/json_io.h"
#include "core/io/rig_folder.h"

namespace calibench {

bool BrushFitsImage(const BrushMask& mask, int rows, int columns, std::string* why) {
  if (mask.rows == rows && mask.columns == columns) return true;
  if (why)
    *why = "the brush mask was painted on a " + std::to_string(mask.rows) + "x" +
           std::to_string(mask.columns) + " LiDAR image, but this cloud gives " +
           std::to_string(rows) + "x" + std::to_string(columns) + "; paint the board again";
  return false;
}

bool SessionResult::operator==(const SessionResult& other) const {
  return cam_from_lidar.matrix() == other.cam_from_lidar.matrix() &&
         covariance == other.covariance && iterations == other.iterations &&
         converged == other.converged && cost_history == other.cost_history &&
         weak_directions == other.weak_directions && well_constrained == other.well_constrained &&
         step_history == other.step_history &&
         reweighted_iterations == other.reweighted_iterations &&
         range_offset == other.range_offset &&
         unmodelled_range_offset == other.unmodelled_range_offset &&
         num_edge_residuals == other.num_edge_residuals && edge_dilation == other.edge_dilation &&
         covariance_inflation == other.covariance_inflation &&
         plane_variance_factor == other.plane_variance_factor &&
         edge_variance_factor == other.edge_variance_factor && termination == other.termination &&
         notes == other.notes && targetless_provenance == other.targetless_provenance &&
         std::equal(estimate_history.begin(), estimate_history.end(),
                    other.estimate_history.begin(), other.estimate_history.end(),
                    [](const Pose& a, const Pose& b) { return a.matrix() == b.matrix(); });
}

SessionResult SessionResultFromSolver(const SolverResult& solver) {
  return {solver.cam_from_lidar,
          solver.covariance,
          solver.iterations,
          solver.converged,
          solver.cost_history,
          solver.observability.weak_directions,
          solver.observability.well_constrained,
          {},
          {},
          {},
          solver.range_offset,
          solver.unmodelled_range_offset,
          solver.num_edge_residuals,
          solver.edge_dilation,
          solver.covariance_inflation,
          solver.plane_variance_factor,
          solver.edge_variance_factor,
          solver.termination,
          {},
          {}};
}

SolverResult SolverResultFromSession(const SessionResult& session, SolverMethod method) {
  SolverResult r;
  r.method = method;
  r.cam_from_lidar = session.cam_from_lidar;
  r.covariance = session.covariance;
  r.iterations = session.iterations;
  r.converged = session.converged;
  r.cost_history = session.cost_history;
  r.observability.weak_directions = session.weak_directions;
  r.observability.well_constrained = session.well_constrained;
  r.range_offset = session.range_offset;
  r.unmodelled_range_offset = session.unmodelled_range_offset;
  r.num_edge_residuals = session.num_edge_residuals;
  r.edge_dilation = session.edge_dilation;
  r.covariance_inflation = session.covariance_inflation;
  r.plane_variance_factor = session.plane_variance_factor;
  r.edge_variance_factor = session.edge_variance_factor;
  r.termination = session.termination;
  return r;
}

std::filesystem::path NormalizeSessionPath(const std::filesystem::path& path) {
  std::filesystem::path p = std::filesystem::absolute(path).lexically_normal();
  // Without a trailing separator, so that "a/b/." and "a/b" compare equal.
  if (!p.has_filename() && p != p.root_path()) p = p.parent_path();
  return p;
}

std::filesystem::path DefaultSessionPath(const std::filesystem::path& dataset,
                                         const std::string& camera) {
  std::error_code error;
  const std::filesystem::path folder =
      std::filesystem::is_directory(dataset, error) ? dataset : dataset.parent_path();
  return folder /
         (camera.empty() ? "calibench.session.json" : "calibench.session." + camera + ".json");
}

Session NewSession(const Dataset& dataset) {
  Session session;
  session.dataset = NormalizeSessionPath(dataset.manifest);
  session.camera = dataset.camera_name;
  for (const PairEntry& entry : dataset.pairs) {
    PairState pair;
    pair.id = entry.id;
    session.pairs.push_back(pair);
  }
  return session;
}

JobSettings JobSettings::Of(const PipelineOptions& options) {
  JobSettings settings;
  PipelineOptions read = options;  // the slots' accessors take the options to write as well
  for (const JobSettingField& field : JobSettingFields())
    std::visit([&](auto slot) { settings.*slot.setting = slot.in_pipeline(read); }, field.slot);
  return settings;
}

void JobSettings::Apply(PipelineOptions* options) const {
  for (const JobSettingField& field : JobSettingFields())
    std::visit([&](auto slot) { slot.in_pipeline(*options) = this->*slot.setting; }, field.slot);
  // Only the weighted method has a range offset to estimate (SolverOptions); the choice stays.
  options->solver.estimate_range_offset =
      estimate_range_offset && method == SolverMethod::kWeightedMl;
}

std::string JobSettingField::Key() const {
  if (!file_key.empty()) return std::string(file_key);
  std::string key(flag);
  std::replace(key.begin(), key.end(), '-', '_');
  return key;
}

const std::vector<JobSettingField>& JobSettingFields() {
  static const std::vector<JobSettingField> fields = {
      {"method", "", "",
       "weighted-ml (default: residuals whitened by both planes' covariances) | ca2lib-gn (the "
       "paper's unweighted Gauss-Newton) | kim (Kim et al. 2020: closed form from the normals, the "
       "paper's baseline)",
       true, SettingSlot<SolverMethod>{&JobSettings::method, InSolver<&SolverOptions::method>}},
      {"huber-delta", "", "Huber delta", "Huber threshold on the plane error", false,
       SettingSlot<double>{&JobSettings::huber_delta, InSolver<&SolverOptions::huber_delta>}},
      {"max-iterations", "", "max iterations", "Gauss-Newton iterations", false,
       SettingSlot<int>{&JobSettings::max_iterations, InSolver<&SolverOptions::max_iterations>}},
      {"estimate-range-offset", "", "",
       "weighted-ml: also estimate a constant LiDAR range offset (printed with its standard "
       "deviation and its correlation with the translation)",
       true,
       SettingSlot<bool>{&JobSettings::estimate_range_offset,
                         InSolver<&SolverOptions::estimate_range_offset>}},
      {"ransac-threshold", "ransac_threshold_m", "", "LiDAR plane RANSAC inlier distance [m]",
       false,
       SettingSlot<double>{&JobSettings::ransac_threshold_m,
                           InLidarPlane<&LidarPlaneOptions::ransac_threshold_m>}},
  };
  return fields;
}

bool JobSettings::Check(std::string* why) const {
  PipelineOptions options;
  Apply(&options);
  if (!options.solver.Check(why)) return false;
  if (!(ransac_threshold_m > 0)) {
    if (why) *why = "ransac_threshold_m must be > 0 (metres)";
    return false;
  }
  return true;
}

PairEdit EditOfPair(const PairState& pair) {
  PairEdit edit;
  edit.rejected = pair.status == PairStatus::kRejected;
  if (pair.brush && !pair.brush_from_seed) {
    edit.brush_pixels = pair.brush->pixels;
    edit.brush_rows = pair.brush->rows;
    edit.brush_columns = pair.brush->columns;
  }
  return edit;
}

PairEdits EditsFromSession(const Session& session) {
  PairEdits edits;
  for (const PairState& pair : session.pairs) {
    PairEdit edit = EditOfPair(pair);
    if (edit.rejected || edit.brush_pixels) edits[pair.id] = std::move(edit);
  }
  return edits;
}

std::map<std::string, PairEdits> RigEditsOfSessions(const RigFolder& rig,
                                                    const std::vector<std::string>& session_paths) {
  std::map<std::string, PairEdits> edits;
  for (const std::string& session_path : session_paths) {
    const Session session = LoadSession(session_path);
    if (session.camera.empty() ||
        NormalizeSessionPath(session.dataset) != NormalizeSessionPath(rig.folder))
      throw IoError(session_path + ": not a session of a camera of the rig " + rig.folder.string() +
                    " (its dataset is " + session.dataset.string() + ")");
    RigCameraIndex(rig, session.camera);  // a camera the rig has, else the error names them
    edits[session.camera] = EditsFromSession(session);
  }
  return edits;
}

bool IsSessionFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  return head.find("calibench.session.v1") != std::string::npos;
}

Session LoadSession(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found)
    throw IoError(path.string() + ": no such session file");
  if (!std::filesystem::is_regular_file(status))  // a FIFO would block, a device never end
    throw IoError(path.string() + ": not a regular file (a folder, a FIFO or a device?)");
  if (std::filesystem::file_size(path, error) > json_io::kMaxJsonBytes)
    throw IoError(path.string() + ": larger than any session file (" +
                  std::to_string(json_io::kMaxJsonBytes >> 20) + " MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path.string() + ": cannot open session file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError(path.string() + ": read failed");
  return SessionFromJson(text.str(), path);
}

void RefuseLrfSession(const Session& session, const std::filesystem::path& path) {
  if (!session.lrf_method.empty())
    throw IoError(path.string() + ": a 2D LRF session (options.lrf_method \"" + session.lrf_method +
                  "\") of " + session.dataset.string() +
                  ", not a LiDAR-camera one; `calibench calibrate --session`, "
                  "`calibench lrf-calibrate --session` and `calibench gui --session` open it");
}

SessionWithDataset LoadSessionWithDataset(const std::filesystem::path& session_path) {
  Session session = LoadSession(session_path);
  RefuseLrfSession(session, session_path);
  // A folder without a board (a drive kept for the targetless check) reopens too.
  Dataset dataset = session.camera.empty()
                        ? LoadDataset(session.dataset, CameraFile::kRequired, TargetFile::kOptional)
                        : LoadRigCamera(session.dataset, session.camera);
  session = SessionOverDataset(std::move(session), dataset, session_path);
  return {std::move(session), std::move(dataset)};
}

Session SessionOverDataset(Session saved, const Dataset& dataset,
                           const std::filesystem::path& session_path) {
  std::vector<std::string> ids;
  for (const PairEntry& entry : dataset.pairs) ids.push_back(entry.id);
  return SessionOverPairs(std::move(saved), ids, dataset.manifest, session_path);
}

Session SessionOverPairs(Session saved, const std::vector<std::string>& ids,
                         const std::filesystem::path& manifest,
                         const std::filesystem::path& session_path) {
  const std::set<std::string> in_dataset(ids.begin(), ids.end());
  for (const PairState& pair : saved.pairs)
    if (!in_dataset.count(pair.id))
      throw IoError(session_path.string() + ": the session's pair '" + pair.id + "' is not in " +
                    manifest.string() + " (" + std::to_string(ids.size()) + " pairs there, " +
                    std::to_string(saved.pairs.size()) + " in the session)");
  std::map<std::string, size_t> saved_index;
  for (size_t i = 0; i < saved.pairs.size(); ++i) saved_index[saved.pairs[i].id] = i;
  std::vector<PairState> pairs;
  size_t next_saved = 0;  // the saved pairs must come in the dataset's order
  for (const std::string& id : ids) {
    const auto found = saved_index.find(id);
    if (found == saved_index.end()) {
      PairState added;
      added.id = id;
      pairs.push_back(std::move(added));
      continue;
    }
    if (found->second != next_saved)
      throw IoError(session_path.string() + ": pair '" + id + "' comes before '" +
                    saved.pairs[next_saved].id + "' in " + manifest.string() +
                    " but after it in the session");
    ++next_saved;
    pairs.push_back(std::move(saved.pairs[found->second]));
  }
  saved.pairs = std::move(pairs);
  return saved;
}

std::optional<FileLock> LockSessionFile(const std::filesystem::path& session,
                                        const std::optional<FileLock>& held, std::string* note) {
  std::error_code ec;
  if (held && std::filesystem::weakly_canonical(held->locked(), ec) ==
                  std::filesystem::weakly_canonical(session, ec))
    return std::nullopt;
  std::string holder;
  try {
    std::optional<FileLock> lock = FileLock::TryLock(session, &holder);
    if (!lock)
      throw IoError(session.string() + ": the session is open in another Calibench workbench (" +
                    holder + "); close it there first, or open a copy of the file");
    return lock;
  } catch (const IoError& e) {
    if (!holder.empty()) throw;
    *note = std::string("cannot lock the session (") + e.what() + ")";
    return std::nullopt;
  }
}

std::filesystem::path ResumeSessionBeside(
    const std::filesystem::path& path, bool fresh,
    const std::function<void(const std::filesystem::path&)>& load, std::string* note) {
  if (fresh) {
    *note = "started over: kept the old session as " + MoveSessionAside(path).string();
    return {};
  }
  try {
    load(path);
    *note = "resumed the session in " + path.string() +
            " (--fresh starts over and keeps it as a backup)";
    return path;
  } catch (const IoError& e) {
    *note = "the session there did not open (" + std::string(e.what()) + "): ";
  }
  for (int n = 1; n <= AutosaveOptions{}.backups; ++n) {
    const std::filesystem::path backup = SessionBackupPath(path, n);
    if (!std::filesystem::exists(backup)) continue;
    try {
      load(backup);
    } catch (const IoError&) {
      continue;  // an older backup, then
    }
    *note += "resumed its newest backup that opens, " + backup.string() +
             "; the one that did not open is kept as " + MoveSessionAside(path).string();
    return backup;
  }
  *note += "kept the old session as " + MoveSessionAside(path).string();
  return {};
}

std::filesystem::path MoveSessionAside(const std::filesystem::path& path) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  std::filesystem::path backup = path.string() + "." + stamp + ".bak";
  for (int n = 2; std::filesystem::exists(backup); ++n)
    backup = path.string() + "." + stamp + "-" + std::to_string(n) + ".bak";
  std::error_code ec;
  std::filesystem::rename(path, backup, ec);
  if (ec)
    throw IoError(path.string() + ": cannot move the session aside to " + backup.string() + " (" +
                  ec.message() + "); it was left as it is");
  return backup;
}

void SaveSession(const std::filesystem::path& path, const Session& session) {
  WriteFileAtomically(path, SessionToJson(session, path));
}

SessionHistory::SessionHistory(std::size_t max_depth) : max_depth_(max_depth) {
  CALIBENCH_CHECK(max_depth >= 1);
}

void SessionHistory::Reset(const Session& state) {
  states_.assign(1, state);
  cursor_ = 0;
}

void SessionHistory::Push(const Session& state) {
  if (states_.empty()) return Reset(state);
  if (state == states_[cursor_]) return;
  states_.erase(states_.begin() + static_cast<std::ptrdiff_t>(cursor_) + 1, states_.end());
  states_.push_back(state);
  ++cursor_;
  if (states_.size() > max_depth_ + 1) {
    states_.pop_front();
    --cursor_;
  }
}

void SessionHistory::Amend(const Session& state) {
  if (states_.empty()) return Reset(state);
  states_[cursor_] = state;
}

std::optional<Session> SessionHistory::Undo() {
  if (!CanUndo()) return std::nullopt;
  return states_[--cursor_];
}

std::optional<Session> SessionHistory::Redo() {
  if (!CanRedo()) return std::nullopt;
  return states_[++cursor_];
}

bool AutosaveOptions::Check(std::string* why) const {
  if (backups < 0 || backups > 100) {
    *why = "backups must be in [0, 100], got " + std::to_string(backups);
    return false;
  }
  if (!(backup_interval_s >= 0.0)) {
    *why = "backup_interval_s must be >= 0";
    return false;
  }
  return true;
}

std::filesystem::path SessionBackupPath(const std::filesystem::path& session, int n) {
  return session.parent_path() /
         (session.stem().string() + ".backup-" + std::to_string(n) + session.extension().string());
}

Autosaver::Autosaver(std::filesystem::path path, AutosaveOptions options)
    : path_(std::move(path)), options_(options) {
  std::string why;
  if (!options_.Check(&why)) throw std::invalid_argument("AutosaveOptions: " + why);
  RemoveStaleTemporaries(path_);
}

void Autosaver::BackUp() {
  const double now =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  if (options_.backups == 0) return;
  if (last_backup_s_ >= 0.0 && now - last_backup_s_ < options_.backup_interval_s) return;
  last_backup_s_ = now;  // due now; a session not yet on disk has nothing to back up
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path_, ec)) return;
  // Oldest first, so that a kill between two renames loses at most the oldest backup.
  for (int n = options_.backups - 1; n >= 1; --n)
    std::filesystem::rename(SessionBackupPath(path_, n), SessionBackupPath(path_, n + 1), ec);
  const std::filesystem::path newest = SessionBackupPath(path_, 1);
  std::filesystem::remove(newest, ec);
  std::filesystem::create_hard_link(path_, newest, ec);
  if (ec) std::filesystem::copy_file(path_, newest, ec);  // filesystems without hard links
  if (ec)
    throw IoError(newest.string() + ": cannot back up the session before saving: " + ec.message());
}

bool Autosaver::Save(const Session& session) {
  std::string text = SessionToJson(session, path_);
  if (has_written_ && text == last_text_) return false;
  BackUp();
  WriteFileAtomically(path_, text);
  last_text_ = std::move(text);
  has_written_ = true;
  ++writes_;
  return true;
}

}  // namespace calibench
