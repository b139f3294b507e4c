// PCD (Point Cloud Library format, v0.5-v0.7): our own header parser and ascii / binary /
// binary_compressed readers and writers. Only the LZF codec comes from PCL.
#include <pcl/io/lzf.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <sstream>

#include "core/base/notice.h"
#include "core/io/cloud_io.h"
#include "core/io/cloud_io_internal.h"
#include "core/lidar/cloud.h"

namespace calibench {
namespace cloud_io_detail {
namespace {

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdField {
  std::string name;
  ScalarType type;
  int count = 1;
  size_t offset = 0;  // bytes from the start of one point record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  size_t point_size = 0;   // bytes per point record
  size_t value_count = 0;  // numbers per ascii row (sum of COUNT)
  uint64_t width = 0, height = 1, points = 0;
  PcdData data = PcdData::kAscii;
  size_t data_start = 0;  // byte offset of the first data byte
  size_t data_line = 0;   // 1-based line number of the first ascii row
  int field_of_role[kNumRoles] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
  static_assert(kNumRoles == 10, "one -1 per role above");
};

// The header keywords, each a list of words, as they appear before DATA.
struct RawHeader {
  std::vector<std::string_view> fields, sizes, types, counts;
  std::string_view width, height, points, data;
};

// The RawHeader member a keyword that takes a list of words (FIELDS, SIZE, ...) fills; null for
// other keywords.
std::vector<std::string_view>* ListKeyword(RawHeader* raw, std::string_view key) {
  if (key == "FIELDS" || key == "COLUMNS") return &raw->fields;
  if (key == "SIZE") return &raw->sizes;
  if (key == "TYPE") return &raw->types;
  if (key == "COUNT") return &raw->counts;
  return nullptr;
}

// The member a keyword that takes one word (WIDTH, HEIGHT, POINTS) fills; null for others.
std::string_view* WordKeyword(RawHeader* raw, std::string_view key) {
  if (key == "WIDTH") return &raw->width;
  if (key == "HEIGHT") return &raw->height;
  if (key == "POINTS") return &raw->points;
  return nullptr;
}

std::string Joined(const std::vector<std::string_view>& words) {
  std::string text;
  for (const auto& w : words) text += (text.empty() ? "" : " ") + std::string(w);
  return text;
}

RawHeader ReadRawHeader(const std::filesystem::path& path, const std::string& bytes,
                        PcdHeader* header) {
  RawHeader raw;
  size_t pos = 0, line_number = 0;
  while (pos < bytes.size()) {
    size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    const std::string_view line(bytes.data() + pos, eol - pos);
    pos = std::min(eol + 1, bytes.size());
    ++line_number;
    const auto words = SplitWords(line);
    if (words.empty() || words[0][0] == '#') continue;
    const std::string_view key = words[0];
    const std::vector<std::string_view> values(words.begin() + 1, words.end());
    const std::string_view first = values.empty() ? std::string_view() : values[0];
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (auto* list = ListKeyword(&raw, key)) {
      *list = values;
      continue;
    }
    if (auto* word = WordKeyword(&raw, key)) {
      *word = first;
      continue;
    }
    if (key == "DATA") {
      raw.data = first;
      header->data_start = pos;
      header->data_line = line_number + 1;
      return raw;
    } else {
      Fail(path, "unexpected PCD header line " + std::to_string(line_number) + " '" +
                     std::string(line.substr(0, 60)) + "' (is this a PCD file?)");
    }
  }
  Fail(path, "PCD header has no DATA line (is this a PCD file?)");
}

ScalarType ParseFieldType(const std::filesystem::path& path, const std::string& name,
                          std::string_view type, uint64_t size) {
  const std::string where =
      "field '" + name + "' has TYPE " + std::string(type) + " with SIZE " + std::to_string(size);
  if (type == "F") {
    if (size != 4 && size != 8) Fail(path, where + " (F needs SIZE 4 or 8)");
    return {ScalarKind::kFloat, static_cast<int>(size)};
  }
  if (type == "I" || type == "U") {
    if (size != 1 && size != 2 && size != 4 && size != 8)
      Fail(path, where + " (" + std::string(type) + " needs SIZE 1, 2, 4 or 8)");
    return {type == "I" ? ScalarKind::kSigned : ScalarKind::kUnsigned, static_cast<int>(size)};
  }
  Fail(path, "field '" + name + "' has unknown TYPE '" + std::string(type) + "'");
}

uint64_t ParseHeaderNumber(const std::filesystem::path& path, std::string_view key,
                           std::string_view token) {
  uint64_t value = 0;
  if (!ParseSize(token, &value))
    Fail(path, "bad " + std::string(key) + " value '" + std::string(token) + "' in PCD header");
  return value;
}

void ParseFields(const std::filesystem::path& path, const RawHeader& raw, PcdHeader* header) {
  const size_t n = raw.fields.size();
  if (n == 0) Fail(path, "PCD header has no FIELDS line");
  if (raw.sizes.size() != n)
    Fail(path, "PCD header has " + std::to_string(n) + " FIELDS but " +
                   std::to_string(raw.sizes.size()) + " SIZE entries");
  // Old (v0.5) headers may omit TYPE (all floats) and COUNT (all 1).
  if (!raw.types.empty() && raw.types.size() != n)
    Fail(path, "PCD header has " + std::to_string(n) + " FIELDS but " +
                   std::to_string(raw.types.size()) + " TYPE entries");
  if (!raw.counts.empty() && raw.counts.size() != n)
    Fail(path, "PCD header has " + std::to_string(n) + " FIELDS but " +
                   std::to_string(raw.counts.size()) + " COUNT entries");
  for (size_t i = 0; i < n; ++i) {
    PcdField field;
    field.name = std::string(raw.fields[i]);
    const uint64_t size = ParseHeaderNumber(path, "SIZE", raw.sizes[i]);
    field.type = ParseFieldType(path, field.name, raw.types.empty() ? "F" : raw.types[i], size);
    const uint64_t count = raw.counts.empty() ? 1 : ParseHeaderNumber(path, "COUNT", raw.counts[i]);
    if (count == 0 || count > 1 << 20)
      Fail(path, "field '" + field.name + "' has COUNT " + std::to_string(count));
    field.count = static_cast<int>(count);
    field.offset = header->point_size;
    header->point_size += size * count;
    header->value_count += count;
    const FieldRole role = RoleOfName(field.name);
    if (role != kIgnored && header->field_of_role[role] < 0)
      header->field_of_role[role] = static_cast<int>(i);
    header->fields.push_back(field);
  }
  for (const FieldRole role : {kX, kY, kZ}) {
    if (header->field_of_role[role] < 0)
      Fail(path, std::string("PCD header has no '") + "xyz"[role] + "' field (FIELDS " +
                     Joined(raw.fields) + ")");
  }
}

void ParseLayout(const std::filesystem::path& path, const RawHeader& raw, PcdHeader* header) {
  const bool has_width = !raw.width.empty(), has_points = !raw.points.empty();
  header->height = raw.height.empty() ? 1 : ParseHeaderNumber(path, "HEIGHT", raw.height);
  if (has_width) header->width = ParseHeaderNumber(path, "WIDTH", raw.width);
  if (has_points) header->points = ParseHeaderNumber(path, "POINTS", raw.points);
  if (!has_width && !has_points) Fail(path, "PCD header has neither WIDTH nor POINTS");
  if (!has_points) header->points = header->width * header->height;
  if (!has_width) {
    header->height = 1;
    header->width = header->points;
  }
  if (header->width * header->height != header->points)
    Fail(path, "PCD header WIDTH x HEIGHT = " + std::to_string(header->width) + " x " +
                   std::to_string(header->height) + " does not match POINTS " +
                   std::to_string(header->points));
  if (header->points > (uint64_t{1} << 31)) Fail(path, "PCD header has too many POINTS");
  if (raw.data == "ascii")
    header->data = PcdData::kAscii;
  else if (raw.data == "binary")
    header->data = PcdData::kBinary;
  else if (raw.data == "binary_compressed")
    header->data = PcdData::kBinaryCompressed;
  else
    Fail(path, "unknown PCD DATA type '" + std::string(raw.data) +
                   "' (expected ascii, binary or binary_compressed)");
}

void HasRoles(const PcdHeader& header, bool has[kNumRoles]) {
  for (int r = 0; r < kNumRoles; ++r) has[r] = header.field_of_role[r] >= 0;
}

// Binary records: field f of point i lives at base[f] + i * stride[f]. Interleaved (binary) and
// field-by-field (binary_compressed, after decompression) layouts differ only in base/stride.
void ReadRecords(const PcdHeader& header, const char* data, bool field_major,
                 CloudBuilder* builder) {
  size_t base[kNumRoles] = {}, stride[kNumRoles] = {};
  ScalarType type[kNumRoles];
  for (int r = 0; r < kNumRoles; ++r) {
    if (header.field_of_role[r] < 0) continue;
    const PcdField& field = header.fields[header.field_of_role[r]];
    base[r] = field_major ? header.points * field.offset : field.offset;
    stride[r] =
        field_major ? field.type.bytes * static_cast<size_t>(field.count) : header.point_size;
    type[r] = field.type;
  }
  double values[kNumRoles] = {};
  for (size_t i = 0; i < header.points; ++i) {
    for (int r = 0; r < kNumRoles; ++r) {
      if (header.field_of_role[r] >= 0)
        values[r] = ReadScalar(data + base[r] + i * stride[r], type[r], false);
    }
    builder->Add(values);
  }
}

// Data after what the header describes is read as PCL reads it (not at all), and said once.
void NoteTrailingData(const std::filesystem::path& path, const std::string& what) {
  NoteOnce("pcd-trailing-data",
           path.string() + ": " + what +
               " ignored, as PCL reads it (the header's POINTS are the points)");
}

// Rows are scanned in place: tokens are found by pointer, only the role columns are parsed
// (std::from_chars), and nothing is allocated per row (the line number is put into words only
// when a row fails): 363 MB/s on a real VLP-16 cloud, against 149 MB/s when each row was split
// into a vector of words (BM_LoadAsciiPcdReal).
void ReadAscii(const std::filesystem::path& path, const std::string& bytes, const PcdHeader& header,
               CloudBuilder* builder) {
  // An ascii row lists every field's COUNT values in order; a role reads its field's first one.
  std::vector<int> role_of_column(header.value_count, -1);
  for (int r = 0; r < kNumRoles; ++r) {
    if (header.field_of_role[r] < 0) continue;
    size_t column = 0;
    for (int f = 0; f < header.field_of_role[r]; ++f) column += header.fields[f].count;
    role_of_column[column] = r;
  }
  auto is_space = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  };
  double values[kNumRoles] = {};
  const char* cursor = bytes.data() + std::min(header.data_start, bytes.size());
  const char* const end = bytes.data() + bytes.size();
  size_t line_number = header.data_line - 1;
  uint64_t rows = 0;
  while (rows < header.points && cursor < end) {
    const char* eol = static_cast<const char*>(std::memchr(cursor, '\n', end - cursor));
    if (!eol) eol = end;
    ++line_number;
    size_t column = 0;
    const char* p = cursor;
    while (true) {
      while (p < eol && is_space(*p)) ++p;
      if (p == eol) break;
      const char* token = p;
      while (p < eol && !is_space(*p)) ++p;
      const int role = column < role_of_column.size() ? role_of_column[column] : -1;
      if (role >= 0 && !ParseDouble(std::string_view(token, p - token), &values[role]))
        Fail(path, "line " + std::to_string(line_number) + ": cannot parse '" +
                       std::string(token, p) + "' as a number (field '" +
                       header.fields[header.field_of_role[role]].name + "')");
      ++column;
    }
    cursor = eol + 1;
    if (column == 0) continue;
    if (column < header.value_count)
      Fail(path, "line " + std::to_string(line_number) + " has " + std::to_string(column) +
                     " values, expected " + std::to_string(header.value_count) +
                     " (truncated ascii row?)");
    builder->Add(values);
    ++rows;
  }
  if (rows < header.points)
    Fail(path, "expected " + std::to_string(header.points) + " points of ascii data, file has " +
                   std::to_string(rows) + " rows");
  // Rows beyond POINTS: PCL reads POINTS rows and stops, and so do we (said once).
  for (const char* rest = cursor; rest < end; ++rest)
    if (!is_space(*rest) && *rest != '\n') {
      NoteTrailingData(path, "ascii rows beyond the POINTS " + std::to_string(header.points) +
                                 " it declares (from line " + std::to_string(line_number + 1) +
                                 " on)");
      break;
    }
}

void ReadCompressed(const std::filesystem::path& path, const std::string& bytes,
                    const PcdHeader& header, CloudBuilder* builder) {
  const size_t available = bytes.size() - header.data_start;
  if (available < 8) Fail(path, "binary_compressed data is missing its 8-byte size header");
  const char* data = bytes.data() + header.data_start;
  const ScalarType u4{ScalarKind::kUnsigned, 4};
  const auto compressed = static_cast<size_t>(ReadScalar(data, u4, false));
  const auto uncompressed = static_cast<size_t>(ReadScalar(data + 4, u4, false));
  const size_t expected = header.points * header.point_size;
  if (uncompressed != expected)
    Fail(path, "binary_compressed block holds " + std::to_string(uncompressed) +
                   " bytes, but POINTS x point size = " + std::to_string(expected));
  if (available - 8 < compressed)
    Fail(path, "expected " + std::to_string(compressed) +
                   " bytes of compressed point data, file has " + std::to_string(available - 8));
  // Bytes after the block (zeros a writer left in a file it sized first): PCL decompresses the
  // block the header names and reads no further, and so do we.
  if (available - 8 > compressed)
    NoteTrailingData(path, std::to_string(available - 8 - compressed) +
                               " bytes after its binary_compressed block");
  std::vector<char> raw(expected);
  if (expected > 0 && pcl::lzfDecompress(data + 8, static_cast<unsigned>(compressed), raw.data(),
                                         static_cast<unsigned>(expected)) != expected)
    Fail(path, "LZF decompression of binary_compressed data failed (corrupt file)");
  ReadRecords(header, raw.data(), /*field_major=*/true, builder);
}

}  // namespace

LidarCloud LoadPcd(const std::filesystem::path& path, const LoadLimits& limits) {
  const std::string bytes = ReadWholeFile(path);
  PcdHeader header;
  const RawHeader raw = ReadRawHeader(path, bytes, &header);
  ParseFields(path, raw, &header);
  ParseLayout(path, raw, &header);
  CheckLoadLimit(path, "POINTS", static_cast<std::int64_t>(header.points), limits.max_cloud_points,
                 "max_cloud_points");
  bool has[kNumRoles];
  HasRoles(header, has);
  CloudBuilder builder(path, has, std::min<size_t>(header.points, bytes.size()));
  if (has[kTime]) {
    const PcdField& time = header.fields[header.field_of_role[kTime]];
    const bool integer = time.type.kind != ScalarKind::kFloat;
    builder.TimeFieldIs(
        {time.name, integer,
         std::string(integer ? (time.type.kind == ScalarKind::kSigned ? "I" : "U") : "F") +
             std::to_string(time.type.bytes)});
  }
  switch (header.data) {
    case PcdData::kAscii:
      ReadAscii(path, bytes, header, &builder);
      break;
    case PcdData::kBinary: {
      const size_t expected = header.points * header.point_size;
      const size_t available = bytes.size() - header.data_start;
      if (available < expected)
        Fail(path, "expected " + std::to_string(expected) + " bytes of point data (POINTS x " +
                       "point size), file has " + std::to_string(available));
      // As PCL: POINTS x point size bytes are the points; what follows is not read.
      if (available > expected)
        NoteTrailingData(
            path, std::to_string(available - expected) + " bytes after its binary point data");
      ReadRecords(header, bytes.data() + header.data_start, /*field_major=*/false, &builder);
      break;
    }
    case PcdData::kBinaryCompressed:
      ReadCompressed(path, bytes, header, &builder);
      break;
  }
  return builder.Finish(static_cast<int>(header.width), static_cast<int>(header.height));
}

namespace {

// Shortest text that reads back to the same float.
void AppendNumber(std::string* out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

struct OutField {
  const char* name;
  int size;
  char type;
};

std::vector<OutField> OutFields(const LidarCloud& cloud) {
  std::vector<OutField> fields = {{"x", 4, 'F'}, {"y", 4, 'F'}, {"z", 4, 'F'}};
  if (cloud.HasIntensity()) fields.push_back({"intensity", 4, 'F'});
  if (cloud.HasRing()) fields.push_back({"ring", 2, 'U'});
  if (!cloud.range.empty()) fields.push_back({"range", 4, 'F'});
  if (cloud.HasViewpoint())
    for (const char* name : {"vp_x", "vp_y", "vp_z"}) fields.push_back({name, 4, 'F'});
  if (cloud.HasTime()) fields.push_back({"t", 4, 'F'});  // seconds after lidar_stamp_ns
  return fields;
}

std::string PcdHeaderText(const LidarCloud& cloud, PcdEncoding encoding) {
  const auto fields = OutFields(cloud);
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format (written by calibench)\nVERSION 0.7\nFIELDS";
  for (const auto& f : fields) h << ' ' << f.name;
  h << "\nSIZE";
  for (const auto& f : fields) h << ' ' << f.size;
  h << "\nTYPE";
  for (const auto& f : fields) h << ' ' << f.type;
  h << "\nCOUNT";
  for (size_t i = 0; i < fields.size(); ++i) h << " 1";
  const bool organized = cloud.IsOrganized();
  h << "\nWIDTH " << (organized ? static_cast<size_t>(cloud.width) : cloud.size()) << "\nHEIGHT "
    << (organized ? cloud.height : 1) << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << cloud.size()
    << "\nDATA "
    << (encoding == PcdEncoding::kAscii    ? "ascii"
        : encoding == PcdEncoding::kBinary ? "binary"
                                           : "binary_compressed")
    << '\n';
  return h.str();
}

std::string AsciiBody(const std::filesystem::path& path, const LidarCloud& cloud) {
  std::string body;
  body.reserve(cloud.size() * 48);
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (k) body += ' ';
      AppendNumber(&body, cloud.points[i][k]);
    }
    if (cloud.HasIntensity()) AppendNumber(&(body += ' '), cloud.intensity[i]);
    if (cloud.HasRing()) body += ' ' + std::to_string(RingAsU16(path, cloud.ring[i]));
    if (!cloud.range.empty()) AppendNumber(&(body += ' '), cloud.range[i]);
    if (cloud.HasViewpoint())
      for (int k = 0; k < 3; ++k) AppendNumber(&(body += ' '), cloud.viewpoint[i][k]);
    if (cloud.HasTime()) AppendNumber(&(body += ' '), cloud.time_s[i]);
    body += '\n';
  }
  return body;
}

// Point-major (binary) or field-major (the layout binary_compressed compresses) records.
std::string BinaryBody(const std::filesystem::path& path, const LidarCloud& cloud,
                       bool field_major) {
  std::string body;
  const size_t n = cloud.size();
  auto append_channel = [&](size_t i, int channel) {
    if (channel < 3)
      AppendBytes(&body, cloud.points[i][channel]);
    else if (channel == 3)
      AppendBytes(&body, cloud.intensity[i]);
    else if (channel == 4)
      AppendBytes(&body, RingAsU16(path, cloud.ring[i]));
    else if (channel == 5)
      AppendBytes(&body, cloud.range[i]);
    else if (channel < 9)
      AppendBytes(&body, cloud.viewpoint[i][channel - 6]);
    else
      AppendBytes(&body, cloud.time_s[i]);
  };
  std::vector<int> channels = {0, 1, 2};
  if (cloud.HasIntensity()) channels.push_back(3);
  if (cloud.HasRing()) channels.push_back(4);
  if (!cloud.range.empty()) channels.push_back(5);
  if (cloud.HasViewpoint()) channels.insert(channels.end(), {6, 7, 8});
  if (cloud.HasTime()) channels.push_back(9);
  if (field_major) {
    for (const int c : channels)
      for (size_t i = 0; i < n; ++i) append_channel(i, c);
  } else {
    for (size_t i = 0; i < n; ++i)
      for (const int c : channels) append_channel(i, c);
  }
  return body;
}

std::string CompressedBody(const std::filesystem::path& path, const LidarCloud& cloud) {
  const std::string raw = BinaryBody(path, cloud, /*field_major=*/true);
  // LZF output is at most ~104% of the input; leave room for tiny inputs too.
  std::vector<char> packed(raw.size() + raw.size() / 16 + 64);
  unsigned compressed = 0;
  if (!raw.empty()) {
    compressed = pcl::lzfCompress(raw.data(), static_cast<unsigned>(raw.size()), packed.data(),
                                  static_cast<unsigned>(packed.size()));
    if (compressed == 0) Fail(path, "LZF compression failed");
  }
  std::string body;
  AppendBytes(&body, static_cast<uint32_t>(compressed));
  AppendBytes(&body, static_cast<uint32_t>(raw.size()));
  body.append(packed.data(), compressed);
  return body;
}

}  // namespace
}  // namespace cloud_io_detail

void SavePcd(const std::filesystem::path& path, const LidarCloud& cloud, PcdEncoding encoding) {
  using namespace cloud_io_detail;
  CheckCloudForWriting(path, cloud);
  // Build everything first so that a bad ring value leaves no half-written file behind.
  const std::string header = PcdHeaderText(cloud, encoding);
  const std::string body = encoding == PcdEncoding::kAscii    ? AsciiBody(path, cloud)
                           : encoding == PcdEncoding::kBinary ? BinaryBody(path, cloud, false)
                                                              : CompressedBody(path, cloud);
  std::ofstream out = OpenForWriting(path);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  CloseAfterWriting(out, path);
}

}  // namespace calibench
