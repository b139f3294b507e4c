// The calibench.session.v1 file: Session <-> JSON text, with every field validated on reading.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>

#include "core/session/session.h"

namespace calibench {
using Json = nlohmann::ordered_json;  // keeps "format" first, fields in a readable order

namespace {

constexpr char kFormat[] = "calibench.session.v1";
constexpr int kVersion = 1;
// Far above any LiDAR image (128 rings x 4096 bins = 2^19); keeps a corrupt file from asking
// for gigabytes.
constexpr long long kMaxImagePixels = 1LL << 26;
constexpr char kDirection[] = "x_in_cam = cam_from_lidar * x_in_lidar (camera from LiDAR)";

// A problem inside the file; the loader prefixes the file name when it becomes an IoError.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename Enum>
using NameTable = std::vector<std::pair<Enum, const char*>>;

const NameTable<PairStatus> kStatusNames = {{PairStatus::kPending, "pending"},
                                            {PairStatus::kAccepted, "accepted"},
                                            {PairStatus::kRejected, "rejected"},
                                            {PairStatus::kFailed, "failed"}};
const NameTable<LidarChannel> kChannelNames = {{LidarChannel::kIntensity, "intensity"},
                                               {LidarChannel::kRange, "range"},
                                               {LidarChannel::kRing, "ring"}};
const NameTable<CameraImageMode> kImageModeNames = {{CameraImageMode::kRaw, "raw"},
                                                    {CameraImageMode::kUndistorted, "undistorted"}};
const NameTable<VisibilityMode> kVisibilityNames = {{VisibilityMode::kHpr, "hpr"},
                                                    {VisibilityMode::kZBuffer, "zbuffer"},
                                                    {VisibilityMode::kNone, "none"}};

template <typename Enum>
std::string NameOf(const NameTable<Enum>& table, Enum value) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  CALIBENCH_CHECK(false);
  return "";
}

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

Json ViewToJson(const ViewState& v) {
  return {{"selected_pair", v.selected_pair},
          {"lidar_channel", LidarChannelName(v.lidar_channel)},
          {"camera_image", CameraImageModeName(v.camera_image)},
          {"visibility", VisibilityModeName(v.visibility)},
          {"hpr_radius_exponent", Number(v.hpr_radius_exponent)},
          {"point_size_px", Number(v.point_size_px)},
          {"point_opacity", Number(v.point_opacity)},
          {"orbit_yaw_rad", Number(v.orbit_yaw_rad)},
          {"orbit_pitch_rad", Number(v.orbit_pitch_rad)},
          {"orbit_distance_m", Number(v.orbit_distance_m)},
          {"orbit_target_m", Numbers(v.orbit_target.data(), 3)},
          {"brush_radius_px", Number(v.brush_radius_px)}};
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
      {"board_edge_points", r.num_edge_residuals},
      {"covariance_inflation", r.covariance_inflation},
      {"plane_variance_factor", r.plane_variance_factor},
      {"edge_variance_factor", r.edge_variance_factor}};
  if (r.range_offset) json["lidar_range_offset"] = RangeOffsetToJson(*r.range_offset);
  if (r.unmodelled_range_offset)
    json["unmodelled_lidar_range_offset"] = RangeOffsetToJson(*r.unmodelled_range_offset);
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

double AsDouble(const Json& value, const std::string& path) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const std::string& s = value.get_ref<const std::string&>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
  }
  throw FormatError(path + ": must be a number, found " + value.dump());
}

int ToInt(const Json& value, const std::string& path) {
  // Unsigned first: a huge unsigned read as signed would wrap to a small negative number.
  if (value.is_number_unsigned()) {
    if (value.get<std::uint64_t>() <= std::numeric_limits<int>::max()) return value.get<int>();
  } else if (value.is_number_integer()) {
    const auto v = value.get<std::int64_t>();
    if (v >= std::numeric_limits<int>::min()) return static_cast<int>(v);
  }
  throw FormatError(path + ": must be an integer, found " + value.dump());
}

const Json& ArrayOf(const Json& value, size_t size, const std::string& path) {
  if (!value.is_array() || (size > 0 && value.size() != size))
    throw FormatError(path + ": must be an array" +
                      (size > 0 ? " of " + std::to_string(size) + " entries" : std::string()));
  return value;
}

// The members of one JSON object, each read with its path ("pairs[2].status") for messages.
class Fields {
 public:
  Fields(const Json& object, std::string where) : object_(object), where_(std::move(where)) {
    if (!object.is_object())
      throw FormatError((where_.empty() ? "top level" : where_) + ": must be a JSON object");
  }
  std::string Path(const std::string& key) const {
    return where_.empty() ? key : where_ + "." + key;
  }
  const Json& At(const std::string& key) const {
    const auto it = object_.find(key);
    if (it == object_.end()) throw FormatError(Path(key) + ": missing");
    return *it;
  }
  bool Has(const std::string& key) const {
    return object_.contains(key) && !object_.at(key).is_null();
  }
  Fields Object(const std::string& key) const { return Fields(At(key), Path(key)); }
  const Json& Array(const std::string& key, size_t size = 0) const {
    return ArrayOf(At(key), size, Path(key));
  }
  double Number(const std::string& key) const { return AsDouble(At(key), Path(key)); }
  double Positive(const std::string& key) const {
    const double value = Number(key);
    if (!(value > 0) || !std::isfinite(value))
      throw FormatError(Path(key) + ": must be a positive number");
    return value;
  }
  int Int(const std::string& key) const { return ToInt(At(key), Path(key)); }
  bool Bool(const std::string& key) const {
    if (!At(key).is_boolean()) throw FormatError(Path(key) + ": must be true or false");
    return At(key).get<bool>();
  }
  std::string String(const std::string& key) const {
    if (!At(key).is_string()) throw FormatError(Path(key) + ": must be a string");
    return At(key).get<std::string>();
  }
  template <typename Enum>
  Enum Name(const std::string& key, const NameTable<Enum>& table) const {
    const std::string name = String(key);
    std::string known;
    for (const auto& [value, n] : table) {
      if (name == n) return value;
      known += (known.empty() ? "" : ", ") + std::string(n);
    }
    throw FormatError(Path(key) + ": unknown value \"" + name + "\" (expected one of " + known +
                      ")");
  }

 private:
  const Json& object_;
  std::string where_;
};

BrushMask ReadBrush(const Fields& f) {
  BrushMask mask;
  mask.rows = f.Int("image_rows");
  mask.columns = f.Int("image_columns");
  if (mask.rows < 1 || mask.columns < 1)
    throw FormatError(f.Path("image_rows") + ", image_columns: must be at least 1");
  const long long size = static_cast<long long>(mask.rows) * mask.columns;
  if (size > kMaxImagePixels) throw FormatError(f.Path("image_rows") + ": image too large");
  const Json& runs = f.Array("pixel_runs");
  long long next_free = 0;  // runs ascend without overlapping, so pixels stay sorted and unique
  for (size_t i = 0; i < runs.size(); ++i) {
    const std::string path = f.Path("pixel_runs") + "[" + std::to_string(i) + "]";
    ArrayOf(runs[i], 2, path + " ([start, count])");
    const long long start = ToInt(runs[i][0], path + "[0]");
    const long long count = ToInt(runs[i][1], path + "[1]");
    if (count < 1) throw FormatError(path + ": count must be at least 1");
    if (start < next_free) throw FormatError(path + ": runs must be sorted and must not overlap");
    if (start + count > size)
      throw FormatError(path + ": pixels " + std::to_string(start) + ".." +
                        std::to_string(start + count - 1) + " lie outside the " +
                        std::to_string(mask.rows) + "x" + std::to_string(mask.columns) +
                        " LiDAR image");
    for (long long p = start; p < start + count; ++p) mask.pixels.push_back(static_cast<int>(p));
    next_free = start + count;
  }
  return mask;
}

PairState ReadPair(const Fields& f) {
  PairState pair;
  pair.id = f.String("id");
  if (pair.id.empty()) throw FormatError(f.Path("id") + ": must not be empty");
  pair.status = f.Name("status", kStatusNames);
  pair.reason = f.String("reason");
  f.At("brush");  // required, null when there is no mask
  if (f.Has("brush")) pair.brush = ReadBrush(f.Object("brush"));
  pair.brush_from_seed = f.Bool("brush_from_seed");
  return pair;
}

ViewState ReadView(const Fields& f) {
  ViewState v;
  v.selected_pair = f.String("selected_pair");
  v.lidar_channel = f.Name("lidar_channel", kChannelNames);
  v.camera_image = f.Name("camera_image", kImageModeNames);
  v.visibility = f.Name("visibility", kVisibilityNames);
  v.hpr_radius_exponent = f.Number("hpr_radius_exponent");
  v.point_size_px = f.Positive("point_size_px");
  v.point_opacity = f.Number("point_opacity");
  if (!(v.point_opacity >= 0.0 && v.point_opacity <= 1.0))
    throw FormatError(f.Path("point_opacity") + ": must lie in [0, 1]");
  v.orbit_yaw_rad = f.Number("orbit_yaw_rad");
  v.orbit_pitch_rad = f.Number("orbit_pitch_rad");
  v.orbit_distance_m = f.Positive("orbit_distance_m");
  const Json& target = f.Array("orbit_target_m", 3);
  for (int i = 0; i < 3; ++i) v.orbit_target[i] = AsDouble(target[i], f.Path("orbit_target_m"));
  v.brush_radius_px = f.Positive("brush_radius_px");
  return v;
}

template <int N>
Eigen::Matrix<double, N, N> ReadSquare(const Json& json, const std::string& path) {
  const std::string what = path + " (" + std::to_string(N) + "x" + std::to_string(N) + ")";
  ArrayOf(json, N, what);
  Eigen::Matrix<double, N, N> m;
  for (int r = 0; r < N; ++r) {
    ArrayOf(json[r], N, what);
    for (int c = 0; c < N; ++c) m(r, c) = AsDouble(json[r][c], what);
  }
  return m;
}

RangeOffsetEstimate ReadRangeOffset(const Fields& o) {
  RangeOffsetEstimate offset;
  offset.value_m = o.Number("value_m");
  offset.sigma_m = o.Number("sigma_m");
  const Json& c = o.Array("correlation_with_translation", 3);
  for (int k = 0; k < 3; ++k)
    offset.correlation_with_translation[k] = AsDouble(c[k], o.Path("correlation_with_translation"));
  offset.well_determined = o.Bool("well_determined");
  return offset;
}

SessionResult ReadResult(const Fields& f) {
  SessionResult r;
  const Fields pose = f.Object("cam_from_lidar");
  const Mat4 m = ReadSquare<4>(pose.At("matrix"), pose.Path("matrix"));
  const Mat3 rotation = m.topLeftCorner<3, 3>();
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1) ||
      !((rotation.transpose() * rotation - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6))
    throw FormatError(pose.Path("matrix") + ": not a rigid transform (rotation + translation)");
  r.cam_from_lidar.matrix() = m;
  r.covariance = ReadSquare<6>(f.At("covariance_6x6"), f.Path("covariance_6x6"));
  r.iterations = f.Int("iterations");
  r.converged = f.Bool("converged");
  for (const Json& c : f.Array("cost_history"))
    r.cost_history.push_back(AsDouble(c, f.Path("cost_history")));
  for (const Json& d : f.Array("weak_directions")) {
    if (!d.is_string()) throw FormatError(f.Path("weak_directions") + ": must hold strings");
    r.weak_directions.push_back(d.get<std::string>());
  }
  r.well_constrained = f.Bool("well_constrained");
  // The convergence record is optional: a session without it still opens, without replay.
  if (f.Has("step_history"))
    for (const Json& v : f.Array("step_history"))
      r.step_history.push_back(AsDouble(v, f.Path("step_history")));
  if (f.Has("estimate_history"))
    for (const Json& m : f.Array("estimate_history")) {
      Pose pose = Pose::Identity();
      pose.matrix() = ReadSquare<4>(m, f.Path("estimate_history"));
      r.estimate_history.push_back(pose);
    }
  // Written since the board edges and the range offset; older sessions open without them.
  if (f.Has("board_edge_points")) r.num_edge_residuals = f.Int("board_edge_points");
  if (f.Has("covariance_inflation")) r.covariance_inflation = f.Number("covariance_inflation");
  if (f.Has("plane_variance_factor")) r.plane_variance_factor = f.Positive("plane_variance_factor");
  if (f.Has("edge_variance_factor")) r.edge_variance_factor = f.Positive("edge_variance_factor");
  if (f.Has("lidar_range_offset")) r.range_offset = ReadRangeOffset(f.Object("lidar_range_offset"));
  if (f.Has("unmodelled_lidar_range_offset"))
    r.unmodelled_range_offset = ReadRangeOffset(f.Object("unmodelled_lidar_range_offset"));
  if (f.Has("board_edge_dilation")) {
    const Fields d = f.Object("board_edge_dilation");
    r.edge_dilation =
        EdgeDilationEstimate{d.Number("value_m"), d.Number("sigma_m"), d.Number("spread_m")};
  }
  return r;
}

void ReadOptions(const Fields& f, Session* s) {
  // Sessions written before the method was selectable have no "method": the default applies.
  if (f.Has("method")) {
    const std::string name = f.String("method");
    const auto method = ParseSolverMethod(name);
    if (!method)
      throw FormatError(f.Path("method") + ": '" + name + "' is not weighted-ml, ca2lib-gn or kim");
    s->method = *method;
  }
  // Optional: sessions written before the range offset existed do not estimate it.
  if (f.Has("estimate_range_offset")) s->estimate_range_offset = f.Bool("estimate_range_offset");
  s->huber_delta = f.Positive("huber_delta");
  s->max_iterations = f.Int("max_iterations");
  if (s->max_iterations < 1) throw FormatError(f.Path("max_iterations") + ": must be at least 1");
  s->ransac_threshold_m = f.Positive("ransac_threshold_m");
}

Session ReadSession(const Json& root, const std::filesystem::path& source_path) {
  if (!root.is_object()) throw FormatError("not a Calibench session (not a JSON object)");
  const Fields f(root, "");
  if (!f.Has("format") || f.At("format") != kFormat)
    throw FormatError(std::string("not a Calibench session (format is ") +
                      (f.Has("format") ? f.At("format").dump() : "missing") + ", expected \"" +
                      kFormat + "\")");
  if (f.Int("version") != kVersion)
    throw FormatError("session version " + std::to_string(f.Int("version")) +
                      " is not supported (this build reads version " + std::to_string(kVersion) +
                      ")");
  Session s;
  const std::string dataset = f.String("dataset");
  if (dataset.empty()) throw FormatError("dataset: must not be empty");
  s.dataset = NormalizeSessionPath(NormalizeSessionPath(source_path).parent_path() / dataset);
  ReadOptions(f.Object("options"), &s);
  const Json& pairs = f.Array("pairs");
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::string where = "pairs[" + std::to_string(i) + "]";
    s.pairs.push_back(ReadPair(Fields(pairs[i], where)));
    for (size_t j = 0; j < i; ++j)
      if (s.pairs[j].id == s.pairs[i].id)
        throw FormatError(where + ".id: \"" + s.pairs[i].id + "\" appears twice");
  }
  s.view = ReadView(f.Object("view"));
  if (!s.view.selected_pair.empty() &&
      std::none_of(s.pairs.begin(), s.pairs.end(),
                   [&](const PairState& p) { return p.id == s.view.selected_pair; }))
    throw FormatError("view.selected_pair: \"" + s.view.selected_pair + "\" is not a pair");
  if (f.Has("result")) s.result = ReadResult(f.Object("result"));
  return s;
}

}  // namespace

std::string LidarChannelName(LidarChannel channel) { return NameOf(kChannelNames, channel); }
std::string CameraImageModeName(CameraImageMode mode) { return NameOf(kImageModeNames, mode); }
std::string VisibilityModeName(VisibilityMode mode) { return NameOf(kVisibilityNames, mode); }

std::string SessionToJson(const Session& session, const std::filesystem::path& session_path) {
  CALIBENCH_CHECK(!session.dataset.empty() && session.version == kVersion);
  Json pairs = Json::array();
  for (const PairState& p : session.pairs)
    pairs.push_back({{"id", p.id},
                     {"status", NameOf(kStatusNames, p.status)},
                     {"reason", p.reason},
                     {"brush", p.brush ? BrushToJson(*p.brush) : Json(nullptr)},
                     {"brush_from_seed", p.brush_from_seed}});
  Json root = {{"format", kFormat},
               {"version", session.version},
               {"dataset", DatasetPathForFile(session.dataset, session_path)},
               {"options",
                {{"method", SolverMethodName(session.method)},
                 {"huber_delta", Number(session.huber_delta)},
                 {"estimate_range_offset", session.estimate_range_offset},
                 {"max_iterations", session.max_iterations},
                 {"ransac_threshold_m", Number(session.ransac_threshold_m)}}},
               {"pairs", pairs},
               {"view", ViewToJson(session.view)},
               {"result", session.result ? ResultToJson(*session.result) : Json(nullptr)}};
  std::string text;
  Pretty(root, 0, &text);
  return text + "\n";
}

Session SessionFromJson(const std::string& text, const std::filesystem::path& source_path) {
  const std::string file = source_path.string();
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {
    throw IoError(file + ": not a valid session file (corrupt or truncated JSON): " + e.what());
  }
  try {
    return ReadSession(root, source_path);
  } catch (const FormatError& e) {
    throw IoError(file + ": " + e.what());
  } catch (const Json::exception& e) {
    throw IoError(file + ": malformed session: " + e.what());
  }
}

}  // namespace calibench
