// The calibench.session.v1 file: Session <-> JSON text, with every field validated on reading.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <type_traits>
#include <utility>
#include <variant>

#include "core/base/names.h"
#include "core/io/json_fields.h"
#include "core/io/json_io.h"
#include "core/lrf/solver.h"
#include "core/results/result_json.h"
#include "core/session/session.h"

namespace calibench {
using Json = nlohmann::ordered_json;  // writing: keeps "format" first, fields in a readable order
using json_io::Fields;
using nlohmann::json;  // reading: member order does not matter

namespace {

constexpr char kFormat[] = "calibench.session.v1";
constexpr int kVersion = 1;
// Far above any LiDAR image (128 rings x 4096 bins = 2^19); keeps a corrupt file from asking
// for gigabytes.
constexpr long long kMaxImagePixels = 1LL << 26;
constexpr char kDirection[] = "x_in_cam = cam_from_lidar * x_in_lidar (camera from LiDAR)";

// ---- writing ----

// JSON has no NaN/inf; a session holding one must still load, so they become strings.
Json Number(double value) {
  if (std::isfinite(value)) return value;
  if (std::isnan(value)) return "nan";
  return value > 0 ? "inf" : "-inf";
}

Json Numbers(const double* values, int count) {
  Json out = Json::array();
  for (int i = 0; i < count; ++i) out.push_back(Number(values[i]));
  return out;
}

// Masks are blobs in row-major order, so [start, count] runs are far shorter than pixel lists.
Json BrushToJson(const BrushMask& mask) {
  Json runs = Json::array();
  const long long size = static_cast<long long>(mask.rows) * mask.columns;
  for (size_t i = 0; i < mask.pixels.size(); ++i)  // a broken mask would save an unloadable file
    CALIBENCH_CHECK(mask.pixels[i] >= 0 && mask.pixels[i] < size &&
                    (i == 0 || mask.pixels[i] > mask.pixels[i - 1]));
  for (size_t i = 0; i < mask.pixels.size();) {
    size_t j = i + 1;
    while (j < mask.pixels.size() && mask.pixels[j] == mask.pixels[j - 1] + 1) ++j;
    runs.push_back({mask.pixels[i], static_cast<int>(j - i)});
    i = j;
  }
  return {{"image_rows", mask.rows}, {"image_columns", mask.columns}, {"pixel_runs", runs}};
}

// The workbench's view as it gave it (an object; anything else is a programming error).
Json ViewObject(const std::string& view_json) {
  Json view = Json::parse(view_json);
  CALIBENCH_CHECK(view.is_object());
  return view;
}

Json Rows(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
  for (int r = 0; r < m.rows(); ++r) {
    const Eigen::RowVectorXd row = m.row(r);
    rows.push_back(Numbers(row.data(), static_cast<int>(row.size())));
  }
  return rows;
}

Json EstimateHistory(const std::vector<Pose>& estimates) {
  Json list = Json::array();
  for (const Pose& pose : estimates) list.push_back(Rows(pose.matrix()));
  return list;
}

Json RangeOffsetToJson(const RangeOffsetEstimate& o) {
  return {{"value_m", o.value_m},
          {"sigma_m", o.sigma_m},
          {"correlation_with_translation", Numbers(o.correlation_with_translation.data(), 3)},
          {"well_determined", o.well_determined}};
}

// The settings under their file keys (JobSettingFields), in the order the help lists them.
Json OptionsToJson(const JobSettings& settings) {
  Json options = Json::object();
  for (const JobSettingField& field : JobSettingFields())
    std::visit(
        [&](auto slot) {
          const auto& value = settings.*slot.setting;
          using Value = std::decay_t<decltype(value)>;
          if constexpr (std::is_same_v<Value, SolverMethod>)
            options[field.Key()] = SolverMethodName(value);
          else if constexpr (std::is_same_v<Value, double>)
            options[field.Key()] = Number(value);
          else
            options[field.Key()] = value;
        },
        field.slot);
  return options;
}

Json ResultToJson(const SessionResult& r) {
  Json json = {
      {"direction", kDirection},
      {"cam_from_lidar", {{"matrix", Rows(r.cam_from_lidar.matrix())}}},
      {"covariance_6x6", Rows(r.covariance)},
      {"covariance_convention",
       "right perturbation cam_from_lidar * Exp(delta), delta = [rho (m); phi (rad)]"},
      {"iterations", r.iterations},
      {"converged", r.converged},
      {"cost_history", Numbers(r.cost_history.data(), static_cast<int>(r.cost_history.size()))},
      {"weak_directions", r.weak_directions},
      {"well_constrained", r.well_constrained},
      {"step_history", Numbers(r.step_history.data(), static_cast<int>(r.step_history.size()))},
      {"estimate_history", EstimateHistory(r.estimate_history)},
      {"reweighted_iterations", r.reweighted_iterations},
      {"board_edge_points", r.num_edge_residuals},
      {"covariance_inflation", r.covariance_inflation},
      {"plane_variance_factor", r.plane_variance_factor},
      {"edge_variance_factor", r.edge_variance_factor}};
  if (r.range_offset) json["lidar_range_offset"] = RangeOffsetToJson(*r.range_offset);
  if (r.unmodelled_range_offset)
    json["unmodelled_lidar_range_offset"] = RangeOffsetToJson(*r.unmodelled_range_offset);
  if (r.termination.test != TerminationTest::kNone)
    json["termination"] = TerminationToJson(r.termination);
  if (!r.notes.empty()) json["notes"] = r.notes;
  if (!r.targetless_provenance.empty()) json["targetless_provenance"] = r.targetless_provenance;
  if (r.edge_dilation)
    json["board_edge_dilation"] = {{"value_m", r.edge_dilation->value_m},
                                   {"sigma_m", r.edge_dilation->sigma_m},
                                   {"spread_m", r.edge_dilation->spread_m}};
  return json;
}

// Like dump(2), but arrays of plain values stay on one line: a matrix row, a pixel run or the
// cost history reads as one line instead of one line per number.
void Pretty(const Json& json, int indent, std::string* out) {
  const bool nested =
      std::any_of(json.begin(), json.end(), [](const Json& item) { return item.is_structured(); });
  if (!(json.is_object() && !json.empty()) && !(json.is_array() && nested)) {
    // Replace invalid UTF-8 (say, a Latin-1 file name in a reason) instead of throwing.
    *out += json.dump(-1, ' ', false, Json::error_handler_t::replace);
    return;
  }
  const std::string pad(indent + 2, ' ');
  *out += json.is_object() ? "{\n" : "[\n";
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (it != json.begin()) *out += ",\n";
    *out += pad;
    if (json.is_object())
      *out += Json(it.key()).dump(-1, ' ', false, Json::error_handler_t::replace) + ": ";
    Pretty(*it, indent + 2, out);
  }
  *out += "\n" + std::string(indent, ' ') + (json.is_object() ? "}" : "]");
}

std::string DatasetPathForFile(const std::filesystem::path& dataset,
                               const std::filesystem::path& session_path) {
  const std::filesystem::path absolute = NormalizeSessionPath(dataset);
  if (session_path.empty()) return absolute.string();
  const std::filesystem::path relative =
      absolute.lexically_relative(NormalizeSessionPath(session_path).parent_path());
  // Relative only when the dataset lies in the session's folder tree, so moving that tree moves
  // both; anything else keeps working from wherever the session is copied.
  if (relative.empty() || *relative.begin() == "..") return absolute.string();
  return relative.string();
}

// ---- reading ----

// Every number a session writes may be "nan" or "inf" (Number above).
double StoredNumberAt(const json& value, const Fields& f, const std::string& key) {
  return json_io::NumberAt(value, f.file(), f.Path(key), /*allow_non_finite_strings=*/true);
}

BrushMask ReadBrush(const Fields& f) {
  BrushMask mask;
  mask.rows = f.Int("image_rows");
  mask.columns = f.Int("image_columns");
  if (mask.rows < 1 || mask.columns < 1)
    f.Fail("image_rows", "image_rows and image_columns must be at least 1");
  const long long size = static_cast<long long>(mask.rows) * mask.columns;
  if (size > kMaxImagePixels) f.Fail("image_rows", "image too large");
  const json& runs = f.Array("pixel_runs");
  long long next_free = 0;  // runs ascend without overlapping, so pixels stay sorted and unique
  for (size_t i = 0; i < runs.size(); ++i) {
    const std::string path = f.Path("pixel_runs") + "[" + std::to_string(i) + "]";
    auto fail = [&](const std::string& problem) { json_io::FailAt(f.file(), path, problem); };
    json_io::ArrayAt(runs[i], 2, f.file(), path + " ([start, count])");
    const long long start = json_io::IntAt(runs[i][0], f.file(), path + "[0]");
    const long long count = json_io::IntAt(runs[i][1], f.file(), path + "[1]");
    if (count < 1) fail("count must be at least 1");
    if (start < next_free) fail("runs must be sorted and must not overlap");
    if (start + count > size)
      fail("pixels " + std::to_string(start) + ".." + std::to_string(start + count - 1) +
           " lie outside the " + std::to_string(mask.rows) + "x" + std::to_string(mask.columns) +
           " LiDAR image");
    for (long long p = start; p < start + count; ++p) mask.pixels.push_back(static_cast<int>(p));
    next_free = start + count;
  }
  return mask;
}

PairState ReadPair(const Fields& f) {
  PairState pair;
  pair.id = f.String("id");
  if (pair.id.empty()) f.Fail("id", "must not be empty");
  const std::string status = f.String("status");
  const std::optional<PairStatus> parsed = ParsePairStatus(status);
  if (!parsed)
    f.Fail("status", "unknown value \"" + status +
                         "\" (expected one of pending, accepted, rejected, failed)");
  pair.status = *parsed;
  pair.reason = f.String("reason");
  f.At("brush");  // required, null when there is no mask
  if (f.Has("brush")) pair.brush = ReadBrush(f.Object("brush"));
  pair.brush_from_seed = f.Bool("brush_from_seed");
  return pair;
}

Vec3 ReadVec3(const Fields& f, const std::string& key) {
  const json& values = f.Array(key, 3);
  return Vec3(StoredNumberAt(values[0], f, key), StoredNumberAt(values[1], f, key),
              StoredNumberAt(values[2], f, key));
}

template <int N>
Eigen::Matrix<double, N, N> ReadSquare(const json& value, const Fields& f, const std::string& key) {
  const std::string what = f.Path(key) + " (" + std::to_string(N) + "x" + std::to_string(N) + ")";
  json_io::ArrayAt(value, N, f.file(), what);
  Eigen::Matrix<double, N, N> m;
  for (int r = 0; r < N; ++r) {
    json_io::ArrayAt(value[r], N, f.file(), what);
    for (int c = 0; c < N; ++c)
      m(r, c) = json_io::NumberAt(value[r][c], f.file(), what, /*allow_non_finite_strings=*/true);
  }
  return m;
}

std::vector<double> ReadNumbers(const Fields& f, const std::string& key) {
  std::vector<double> values;
  for (const json& v : f.Array(key)) values.push_back(StoredNumberAt(v, f, key));
  return values;
}

RangeOffsetEstimate ReadRangeOffset(const Fields& o) {
  RangeOffsetEstimate offset;
  offset.value_m = o.StoredNumber("value_m");
  offset.sigma_m = o.StoredNumber("sigma_m");
  offset.correlation_with_translation = ReadVec3(o, "correlation_with_translation");
  offset.well_determined = o.Bool("well_determined");
  return offset;
}

// The optional records, written since the board edges and the range offset: older sessions open
// without them.
void ReadResultExtras(const Fields& f, SessionResult* r) {
  if (f.Has("board_edge_points")) r->num_edge_residuals = f.Int("board_edge_points");
  if (f.Has("covariance_inflation"))
    r->covariance_inflation = f.StoredNumber("covariance_inflation");
  if (f.Has("plane_variance_factor"))
    r->plane_variance_factor = f.Positive("plane_variance_factor");
  if (f.Has("edge_variance_factor")) r->edge_variance_factor = f.Positive("edge_variance_factor");
  if (f.Has("lidar_range_offset"))
    r->range_offset = ReadRangeOffset(f.Object("lidar_range_offset"));
  if (f.Has("unmodelled_lidar_range_offset"))
    r->unmodelled_range_offset = ReadRangeOffset(f.Object("unmodelled_lidar_range_offset"));
  if (f.Has("notes"))  // written since the workbench shows the summary's notes
    for (const json& note : f.Array("notes")) {
      if (!note.is_string()) f.Fail("notes", "must hold strings");
      r->notes.push_back(note.get<std::string>());
    }
  // Written since the workbench adopts a targetless check's estimate.
  if (f.Has("targetless_provenance")) r->targetless_provenance = f.String("targetless_provenance");
  if (f.Has("termination")) {  // written since the solver says which test ended it
    const Fields t = f.Object("termination");
    const std::string name = t.String("test");
    const auto test = ParseTerminationTest(name);
    if (!test) t.Fail("test", "'" + name + "' is not a termination test");
    r->termination = {*test, t.StoredNumber("value"), t.StoredNumber("tolerance"),
                      t.Has("cap") ? t.Int("cap") : 0};
  }
  if (f.Has("board_edge_dilation")) {
    const Fields d = f.Object("board_edge_dilation");
    r->edge_dilation = EdgeDilationEstimate{d.StoredNumber("value_m"), d.StoredNumber("sigma_m"),
                                            d.StoredNumber("spread_m")};
  }
}

SessionResult ReadResult(const Fields& f) {
  SessionResult r;
  const Fields pose = f.Object("cam_from_lidar");
  const Mat4 m = ReadSquare<4>(pose.At("matrix"), pose, "matrix");
  const Mat3 rotation = m.topLeftCorner<3, 3>();
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1) ||
      !((rotation.transpose() * rotation - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6))
    pose.Fail("matrix", "not a rigid transform (rotation + translation)");
  r.cam_from_lidar.matrix() = m;
  r.covariance = ReadSquare<6>(f.At("covariance_6x6"), f, "covariance_6x6");
  r.iterations = f.Int("iterations");
  r.converged = f.Bool("converged");
  r.cost_history = ReadNumbers(f, "cost_history");
  for (const json& d : f.Array("weak_directions")) {
    if (!d.is_string()) f.Fail("weak_directions", "must hold strings");
    r.weak_directions.push_back(d.get<std::string>());
  }
  r.well_constrained = f.Bool("well_constrained");
  // The convergence record is optional: a session without it still opens, without replay.
  if (f.Has("step_history")) r.step_history = ReadNumbers(f, "step_history");
  if (f.Has("estimate_history"))
    for (const json& m : f.Array("estimate_history")) {
      Pose pose = Pose::Identity();
      pose.matrix() = ReadSquare<4>(m, f, "estimate_history");
      r.estimate_history.push_back(pose);
    }
  if (f.Has("reweighted_iterations"))  // written since the cost plot marks them
    for (const json& k : f.Array("reweighted_iterations"))
      r.reweighted_iterations.push_back(
          json_io::IntAt(k, f.file(), f.Path("reweighted_iterations")));
  ReadResultExtras(f, &r);
  return r;
}

// Each setting under its file key (JobSettingFields): a method by name, a number > 0, a count
// >= 1, a flag; one written before a later setting existed keeps that setting's default.
void ReadOptions(const Fields& f, Session* s) {
  JobSettings& settings = s->settings;
  for (const JobSettingField& field : JobSettingFields()) {
    const std::string key = field.Key();
    if (field.optional_in_file && !f.Has(key)) continue;
    std::visit(
        [&](auto slot) {
          auto& value = settings.*slot.setting;
          using Value = std::decay_t<decltype(value)>;
          if constexpr (std::is_same_v<Value, SolverMethod>) {
            const std::string name = f.String(key);
            const auto method = ParseSolverMethod(name);
            if (!method) f.Fail(key, "'" + name + "' is not weighted-ml, ca2lib-gn or kim");
            value = *method;
          } else if constexpr (std::is_same_v<Value, double>) {
            value = f.Positive(key);
          } else if constexpr (std::is_same_v<Value, int>) {
            value = f.Int(key);
            if (value < 1) f.Fail(key, "must be at least 1");
          } else {
            value = f.Bool(key);
          }
        },
        field.slot);
  }
  // Only an LRF session has it (Session::lrf_method).
  if (f.Has("lrf_method")) {
    s->lrf_method = f.String("lrf_method");
    if (!ParseLrfMethod(s->lrf_method))
      f.Fail("lrf_method", "'" + s->lrf_method + "' is not refined or paper-linear");
  }
}

void CheckFormatAndVersion(const Fields& f) {
  const json* format = f.Has("format") ? &f.At("format") : nullptr;
  if (!format || *format != kFormat)
    json_io::FailAt(f.file(), "",
                    std::string("not a Calibench session (format is ") +
                        (format ? format->dump() : "missing") + ", expected \"" + kFormat + "\")");
  if (f.Int("version") != kVersion)
    json_io::FailAt(f.file(), "",
                    "session version " + std::to_string(f.Int("version")) +
                        " is not supported (this build reads version " + std::to_string(kVersion) +
                        ")");
}

Session ReadSession(const json& root, const std::filesystem::path& source_path) {
  if (!root.is_object())
    json_io::FailAt(source_path, "", "not a Calibench session (not a JSON object)");
  const Fields f(root, source_path);
  CheckFormatAndVersion(f);
  Session s;
  const std::string dataset = f.String("dataset");
  if (dataset.empty()) f.Fail("dataset", "must not be empty");
  s.dataset = NormalizeSessionPath(NormalizeSessionPath(source_path).parent_path() / dataset);
  if (f.Has("camera")) {
    s.camera = f.String("camera");
    if (s.camera.empty()) f.Fail("camera", "must name a camera of the rig");
  }
  ReadOptions(f.Object("options"), &s);
  const json& pairs = f.Array("pairs");
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::string where = "pairs[" + std::to_string(i) + "]";
    s.pairs.push_back(ReadPair(Fields(pairs[i], source_path, where)));
    for (size_t j = 0; j < i; ++j)
      if (s.pairs[j].id == s.pairs[i].id)
        json_io::FailAt(source_path, where + ".id", "\"" + s.pairs[i].id + "\" appears twice");
  }
  f.Object("view");  // an object; what it holds is the workbench's (ui/state/view_state.h)
  s.view_json = f.At("view").dump();
  if (f.Has("result")) s.result = ReadResult(f.Object("result"));
  return s;
}

}  // namespace

std::string SessionToJson(const Session& session, const std::filesystem::path& session_path) {
  CALIBENCH_CHECK(!session.dataset.empty() && session.version == kVersion);
  CALIBENCH_CHECK(session.lrf_method.empty() || ParseLrfMethod(session.lrf_method));
  Json pairs = Json::array();
  for (const PairState& p : session.pairs)
    pairs.push_back({{"id", p.id},
                     {"status", PairStatusName(p.status)},
                     {"reason", p.reason},
                     {"brush", p.brush ? BrushToJson(*p.brush) : Json(nullptr)},
                     {"brush_from_seed", p.brush_from_seed}});
  Json root = {{"format", kFormat},
               {"version", session.version},
               {"dataset", DatasetPathForFile(session.dataset, session_path)},
               {"options", OptionsToJson(session.settings)},
               {"pairs", pairs},
               {"view", ViewObject(session.view_json)},
               {"result", session.result ? ResultToJson(*session.result) : Json(nullptr)}};
  if (!session.camera.empty()) root["camera"] = session.camera;
  if (!session.lrf_method.empty()) root["options"]["lrf_method"] = session.lrf_method;
  std::string text;
  Pretty(root, 0, &text);
  return text + "\n";
}

Session SessionFromJson(const std::string& text, const std::filesystem::path& source_path) {
  json_io::CheckJsonNesting(source_path, text);  // the parser recurses
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(source_path.string() +
                  ": not a valid session file (corrupt or truncated JSON): " + e.what());
  }
  try {
    return ReadSession(root, source_path);
  } catch (const json::exception& e) {  // a case the field reader does not cover: still named
    throw IoError(source_path.string() + ": malformed session: " + e.what());
  }
}

}  // namespace calibench
