// The one reader of JSON fields, shared by the dataset manifests (io/dataset.cpp,
// lrf/dataset.cpp), sessions (session/session_json.cpp) and result files
// (results/result_file.cpp). Every problem becomes an IoError "<file>: <path>: <problem>" where
// path locates the field ("pairs[2].status", "camera.fx"), so the user can find and fix it.
// Internal: include it from .cpp files only (it pulls in nlohmann/json).
#pragma once

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "core/base/names.h"
#include "core/base/types.h"

namespace calibench::json_io {

using nlohmann::json;

// IoError "<file>: <path>: <problem>" ("<file>: <problem>" when path is empty).
[[noreturn]] void FailAt(const std::filesystem::path& file, const std::string& path,
                         const std::string& problem);

// A JSON value as a number. Sessions store NaN and infinities as the strings "nan", "inf" and
// "-inf" (JSON has no such numbers); `allow_non_finite_strings` reads those back.
double NumberAt(const json& value, const std::filesystem::path& file, const std::string& path,
                bool allow_non_finite_strings = false);
// A JSON value as an int; rejects fractions and values outside int's range (no silent wrap).
int IntAt(const json& value, const std::filesystem::path& file, const std::string& path);
// The value itself when it is an array (of exactly `size` entries when size > 0).
const json& ArrayAt(const json& value, size_t size, const std::filesystem::path& file,
                    const std::string& path);

// The members of one JSON object in `file`, found at `where` ("" for the top level).
class Fields {
 public:
  // IoError "<where>: must be a JSON object" unless `object` is one.
  Fields(const json& object, std::filesystem::path file, std::string where = "");

  // "<where>.<key>", the name messages give the member.
  std::string Path(const std::string& key) const;
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const;

  // True when the member exists and is not null.
  bool Has(const std::string& key) const;
  // The member; IoError "<path>: missing".
  const json& At(const std::string& key) const;
  // The member as an object (IoError unless it is one).
  Fields Object(const std::string& key) const;
  // The member as an array, of exactly `size` entries when size > 0.
  const json& Array(const std::string& key, size_t size = 0) const;

  double Number(const std::string& key) const;
  // A number, or one of the strings "nan", "inf", "-inf" (sessions).
  double StoredNumber(const std::string& key) const;
  // A finite number > 0.
  double Positive(const std::string& key) const;
  int Int(const std::string& key) const;
  bool Bool(const std::string& key) const;
  std::string String(const std::string& key) const;

  // Any type nlohmann converts to (std::vector<double>, std::uint64_t, ...); IoError
  // "<path>: has the wrong type" otherwise.
  template <typename T>
  T Get(const std::string& key) const {
    try {
      return At(key).get<T>();
    } catch (const json::exception& e) {
      Fail(key, std::string("has the wrong type: ") + e.what());
    }
  }
  // As Get when the member is present and not null, `fallback` otherwise.
  template <typename T>
  T GetOr(const std::string& key, T fallback) const {
    return Has(key) ? Get<T>(key) : fallback;
  }

  // A string naming one entry of an EnumName table; IoError listing the names otherwise.
  template <typename Enum, size_t N>
  Enum Name(const std::string& key, const EnumName<Enum> (&table)[N]) const {
    const std::string name = String(key);
    if (const std::optional<Enum> value = ValueIn(table, name)) return *value;
    Fail(key, "unknown value \"" + name + "\" (expected one of " + NamesIn(table) + ")");
  }

  const json& object() const { return object_; }
  const std::filesystem::path& file() const { return file_; }
  const std::string& where() const { return where_; }

 private:
  const json& object_;
  std::filesystem::path file_;
  std::string where_;
};

}  // namespace calibench::json_io
