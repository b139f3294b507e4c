// PLY (Stanford polygon format): ascii and binary (little/big endian) readers for the vertex
// element, and a binary little-endian writer.
#include <algorithm>
#include <cctype>
#include <sstream>

#include "core/io/cloud_io.h"
#include "core/io/cloud_io_internal.h"
#include "core/lidar/cloud.h"

namespace calibench {
namespace cloud_io_detail {
namespace {

enum class PlyFormat { kAscii, kBinaryLittle, kBinaryBig };

struct PlyProperty {
  std::string name;
  ScalarType type;
  bool is_list = false;
  ScalarType count_type;  // lists only: the type of the leading item count
  FieldRole role = kIgnored;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  bool has_format = false;
  std::vector<PlyElement> elements;
  size_t data_start = 0;
};

bool ParsePlyType(std::string_view name, ScalarType* type) {
  struct Entry {
    const char* a;
    const char* b;
    ScalarType type;
  };
  static const Entry kTypes[] = {
      {"char", "int8", {ScalarKind::kSigned, 1}},
      {"uchar", "uint8", {ScalarKind::kUnsigned, 1}},
      {"short", "int16", {ScalarKind::kSigned, 2}},
      {"ushort", "uint16", {ScalarKind::kUnsigned, 2}},
      {"int", "int32", {ScalarKind::kSigned, 4}},
      {"uint", "uint32", {ScalarKind::kUnsigned, 4}},
      {"float", "float32", {ScalarKind::kFloat, 4}},
      {"double", "float64", {ScalarKind::kFloat, 8}},
  };
  for (const auto& entry : kTypes) {
    if (name == entry.a || name == entry.b) {
      *type = entry.type;
      return true;
    }
  }
  return false;
}

ScalarType PlyType(const std::filesystem::path& path, std::string_view name) {
  ScalarType type;
  if (!ParsePlyType(name, &type))
    Fail(path, "unknown PLY property type '" + std::string(name) + "'");
  return type;
}

void ParsePlyLine(const std::filesystem::path& path, const std::vector<std::string_view>& words,
                  PlyHeader* header) {
  const std::string_view key = words[0];
  if (key == "comment" || key == "obj_info") return;
  if (key == "format" && words.size() >= 2) {
    header->has_format = true;
    if (words[1] == "ascii")
      header->format = PlyFormat::kAscii;
    else if (words[1] == "binary_little_endian")
      header->format = PlyFormat::kBinaryLittle;
    else if (words[1] == "binary_big_endian")
      header->format = PlyFormat::kBinaryBig;
    else
      Fail(path, "unknown PLY format '" + std::string(words[1]) + "'");
  } else if (key == "element" && words.size() == 3) {
    PlyElement element;
    element.name = std::string(words[1]);
    if (!ParseSize(words[2], &element.count))
      Fail(path, "bad PLY element count '" + std::string(words[2]) + "'");
    header->elements.push_back(element);
  } else if (key == "property" && words.size() >= 3) {
    if (header->elements.empty()) Fail(path, "PLY property before any element");
    PlyProperty property;
    if (words[1] == "list") {
      if (words.size() != 5) Fail(path, "malformed PLY list property line");
      property.is_list = true;
      property.count_type = PlyType(path, words[2]);
      property.type = PlyType(path, words[3]);
      property.name = std::string(words[4]);
    } else {
      property.type = PlyType(path, words[1]);
      property.name = std::string(words[2]);
    }
    property.role = property.is_list ? kIgnored : RoleOfName(property.name);
    header->elements.back().properties.push_back(property);
  } else {
    Fail(path, "unexpected PLY header line '" + std::string(key) + " ...'");
  }
}

PlyHeader ParsePlyHeader(const std::filesystem::path& path, const std::string& bytes) {
  PlyHeader header;
  size_t pos = 0;
  bool first = true;
  while (pos < bytes.size()) {
    size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    const auto words = SplitWords(std::string_view(bytes.data() + pos, eol - pos));
    pos = std::min(eol + 1, bytes.size());
    if (first) {
      if (words.size() != 1 || words[0] != "ply") Fail(path, "not a PLY file (no 'ply' magic)");
      first = false;
      continue;
    }
    if (words.empty()) continue;
    if (words[0] == "end_header") {
      if (!header.has_format) Fail(path, "PLY header has no format line");
      header.data_start = pos;
      return header;
    }
    ParsePlyLine(path, words, &header);
  }
  Fail(path, first ? "file is empty" : "PLY header has no end_header line");
}

// Sequential reader over the PLY body: whitespace-separated tokens or packed binary scalars.
class PlyBodyReader {
 public:
  PlyBodyReader(const std::filesystem::path& path, const std::string& bytes, const PlyHeader& h)
      : path_(path), bytes_(bytes), pos_(h.data_start), format_(h.format) {}

  // One scalar of element `element`, row `row` (for error messages).
  double Next(ScalarType type, const PlyElement& element, uint64_t row) {
    double value = 0;
    if (format_ == PlyFormat::kAscii) {
      while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
      const size_t start = pos_;
      while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_])))
        ++pos_;
      if (pos_ == start) Truncated(element, row);
      const std::string_view token(bytes_.data() + start, pos_ - start);
      if (!ParseDouble(token, &value))
        Fail(path_, element.name + " " + std::to_string(row) + ": cannot parse '" +
                        std::string(token) + "' as a number");
      return value;
    }
    if (bytes_.size() - pos_ < static_cast<size_t>(type.bytes)) Truncated(element, row);
    value = ReadScalar(bytes_.data() + pos_, type, format_ == PlyFormat::kBinaryBig);
    pos_ += type.bytes;
    return value;
  }

  // Reads one row; values[role] receives the properties that map to a cloud channel.
  void ReadRow(const PlyElement& element, uint64_t row, double values[kNumRoles]) {
    for (const PlyProperty& property : element.properties) {
      if (!property.is_list) {
        const double value = Next(property.type, element, row);
        if (property.role != kIgnored) values[property.role] = value;
        continue;
      }
      const double count = Next(property.count_type, element, row);
      if (!(count >= 0 && count < 1e6))
        Fail(path_, element.name + " " + std::to_string(row) + ": bad list length " +
                        std::to_string(count) + " for property '" + property.name + "'");
      for (int k = 0; k < static_cast<int>(count); ++k) Next(property.type, element, row);
    }
  }

 private:
  [[noreturn]] void Truncated(const PlyElement& element, uint64_t row) {
    Fail(path_, "PLY data ends inside " + element.name + " " + std::to_string(row) +
                    " (header announces " + std::to_string(element.count) + " " + element.name +
                    " rows; file truncated?)");
  }

  const std::filesystem::path& path_;
  const std::string& bytes_;
  size_t pos_;
  PlyFormat format_;
};

}  // namespace

LidarCloud LoadPly(const std::filesystem::path& path, const LoadLimits& limits) {
  const std::string bytes = ReadWholeFile(path);
  const PlyHeader header = ParsePlyHeader(path, bytes);
  PlyBodyReader reader(path, bytes, header);
  double values[kNumRoles] = {};
  for (const PlyElement& element : header.elements) {
    if (element.name != "vertex") {
      // Elements before the vertices must be read through to find where the vertices start.
      for (uint64_t row = 0; row < element.count; ++row) reader.ReadRow(element, row, values);
      continue;
    }
    bool has[kNumRoles] = {};
    for (const PlyProperty& property : element.properties)
      if (property.role != kIgnored) has[property.role] = true;
    for (const FieldRole role : {kX, kY, kZ}) {
      if (!has[role])
        Fail(path, std::string("PLY vertex element has no '") + "xyz"[role] + "' property");
    }
    CheckLoadLimit(path, "the vertex count", static_cast<std::int64_t>(element.count),
                   limits.max_cloud_points, "max_cloud_points");
    CloudBuilder builder(path, has, std::min<uint64_t>(element.count, bytes.size()));
    for (const PlyProperty& property : element.properties)
      if (property.role == kTime && !property.is_list)
        builder.TimeFieldIs({property.name, property.type.kind != ScalarKind::kFloat,
                             property.type.kind == ScalarKind::kFloat ? "float" : "integer"});
    for (uint64_t row = 0; row < element.count; ++row) {
      reader.ReadRow(element, row, values);
      builder.Add(values);
    }
    // Elements after the vertices (faces, ...) are not needed and are not read.
    return builder.Finish(static_cast<int>(element.count), 1);
  }
  Fail(path, "PLY file has no vertex element");
}

}  // namespace cloud_io_detail

void SavePly(const std::filesystem::path& path, const LidarCloud& cloud) {
  using namespace cloud_io_detail;
  CheckCloudForWriting(path, cloud);
  const bool has_range = !cloud.range.empty();
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment written by calibench (LiDAR frame, "
            "metres)\nelement vertex "
         << cloud.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (cloud.HasIntensity()) header << "property float intensity\n";
  if (cloud.HasRing()) header << "property ushort ring\n";
  if (has_range) header << "property float range\n";
  if (cloud.HasViewpoint())
    header << "property float vp_x\nproperty float vp_y\nproperty float vp_z\n";
  if (cloud.HasTime()) header << "property float t\n";  // seconds after lidar_stamp_ns
  header << "end_header\n";
  std::string body = header.str();
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (int k = 0; k < 3; ++k) AppendBytes(&body, cloud.points[i][k]);
    if (cloud.HasIntensity()) AppendBytes(&body, cloud.intensity[i]);
    if (cloud.HasRing()) AppendBytes(&body, RingAsU16(path, cloud.ring[i]));
    if (has_range) AppendBytes(&body, cloud.range[i]);
    if (cloud.HasViewpoint())
      for (int k = 0; k < 3; ++k) AppendBytes(&body, cloud.viewpoint[i][k]);
    if (cloud.HasTime()) AppendBytes(&body, cloud.time_s[i]);
  }
  std::ofstream out = OpenForWriting(path);
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  CloseAfterWriting(out, path);
}

}  // namespace calibench
