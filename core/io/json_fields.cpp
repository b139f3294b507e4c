#include "core/io/json_fields.h"

#include <cstdint>
#include <limits>

namespace calibench::json_io {
namespace fs = std::filesystem;

[[noreturn]] void FailAt(const fs::path& file, const std::string& path,
                         const std::string& problem) {
  throw IoError(file.string() + ": " + (path.empty() ? "" : path + ": ") + problem);
}

namespace {
// A short rendering of an offending value for messages; a huge array must not flood them.
std::string Shown(const json& value) {
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}
}  // namespace

double NumberAt(const json& value, const fs::path& file, const std::string& path,
                bool allow_non_finite_strings) {
  if (value.is_number()) return value.get<double>();
  if (allow_non_finite_strings && value.is_string()) {
    const std::string& s = value.get_ref<const std::string&>();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
  }
  FailAt(file, path, "must be a number, found " + Shown(value));
}

int IntAt(const json& value, const fs::path& file, const std::string& path) {
  // Unsigned first: a huge unsigned read as signed would wrap to a small negative number.
  if (value.is_number_unsigned()) {
    if (value.get<std::uint64_t>() <= std::numeric_limits<int>::max()) return value.get<int>();
  } else if (value.is_number_integer()) {
    const auto v = value.get<std::int64_t>();
    if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max())
      return static_cast<int>(v);
  }
  FailAt(file, path, "must be an integer, found " + Shown(value));
}

const json& ArrayAt(const json& value, size_t size, const fs::path& file, const std::string& path) {
  if (!value.is_array() || (size > 0 && value.size() != size))
    FailAt(file, path,
           "must be an array" +
               (size > 0 ? " of " + std::to_string(size) + " entries" : std::string()));
  return value;
}

Fields::Fields(const json& object, fs::path file, std::string where)
    : object_(object), file_(std::move(file)), where_(std::move(where)) {
  if (!object.is_object())
    FailAt(file_, where_.empty() ? "top level" : where_, "must be a JSON object");
}

std::string Fields::Path(const std::string& key) const {
  return where_.empty() ? key : where_ + "." + key;
}

void Fields::Fail(const std::string& key, const std::string& problem) const {
  FailAt(file_, Path(key), problem);
}

bool Fields::Has(const std::string& key) const {
  const auto it = object_.find(key);
  return it != object_.end() && !it->is_null();
}

const json& Fields::At(const std::string& key) const {
  const auto it = object_.find(key);
  if (it == object_.end()) Fail(key, "missing");
  return *it;
}

Fields Fields::Object(const std::string& key) const { return Fields(At(key), file_, Path(key)); }

const json& Fields::Array(const std::string& key, size_t size) const {
  return ArrayAt(At(key), size, file_, Path(key));
}

double Fields::Number(const std::string& key) const { return NumberAt(At(key), file_, Path(key)); }

double Fields::StoredNumber(const std::string& key) const {
  return NumberAt(At(key), file_, Path(key), /*allow_non_finite_strings=*/true);
}

double Fields::Positive(const std::string& key) const {
  const double value = StoredNumber(key);
  if (!(value > 0) || !std::isfinite(value)) Fail(key, "must be a positive number");
  return value;
}

int Fields::Int(const std::string& key) const { return IntAt(At(key), file_, Path(key)); }

bool Fields::Bool(const std::string& key) const {
  if (!At(key).is_boolean()) Fail(key, "must be true or false");
  return At(key).get<bool>();
}

std::string Fields::String(const std::string& key) const {
  if (!At(key).is_string()) Fail(key, "must be a string");
  return At(key).get<std::string>();
}

}  // namespace calibench::json_io
