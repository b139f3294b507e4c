// Enums with names in files and on the command line: one table per enum, read both ways.
#pragma once

#include <cctype>
#include <optional>
#include <string>
#include <string_view>

#include "core/base/types.h"

namespace calibench {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// The table's name for `value`; a value missing from its table is a programmer error.
template <typename Enum, size_t N>
std::string NameIn(const EnumName<Enum> (&table)[N], Enum value) {
  for (const EnumName<Enum>& entry : table)
    if (entry.value == value) return entry.name;
  CALIBENCH_CHECK(false && "enum value missing from its name table");
  return "";
}

// The value named `name`; nullopt for any other text.
template <typename Enum, size_t N>
std::optional<Enum> ValueIn(const EnumName<Enum> (&table)[N], const std::string& name) {
  for (const EnumName<Enum>& entry : table)
    if (name == entry.name) return entry.value;
  return std::nullopt;
}

// "a, b, c": the names a table knows, for messages.
template <typename Enum, size_t N>
std::string NamesIn(const EnumName<Enum> (&table)[N]) {
  std::string names;
  for (const EnumName<Enum>& entry : table)
    names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

// Natural order of names, the way people number their files: digit runs compare as numbers, so
// pose2 < pose10 and 9.pcd < 10.pcd; equal numbers with more leading zeros come first
// (007 < 7); everything else compares as bytes.
inline bool NaturalLess(std::string_view a, std::string_view b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool digit_a = std::isdigit(static_cast<unsigned char>(a[i]));
    const bool digit_b = std::isdigit(static_cast<unsigned char>(b[j]));
    if (!digit_a || !digit_b) {
      if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i, ++j;
      continue;
    }
    size_t end_a = i, end_b = j;
    while (end_a < a.size() && std::isdigit(static_cast<unsigned char>(a[end_a]))) ++end_a;
    while (end_b < b.size() && std::isdigit(static_cast<unsigned char>(b[end_b]))) ++end_b;
    size_t start_a = i, start_b = j;  // the digits without leading zeros
    while (start_a + 1 < end_a && a[start_a] == '0') ++start_a;
    while (start_b + 1 < end_b && b[start_b] == '0') ++start_b;
    const std::string_view number_a = a.substr(start_a, end_a - start_a);
    const std::string_view number_b = b.substr(start_b, end_b - start_b);
    if (number_a.size() != number_b.size()) return number_a.size() < number_b.size();
    if (number_a != number_b) return number_a < number_b;
    if (end_a - i != end_b - j) return end_a - i > end_b - j;  // more zeros first
    i = end_a;
    j = end_b;
  }
  return a.size() - i < b.size() - j;
}

struct NaturalOrder {
  bool operator()(std::string_view a, std::string_view b) const { return NaturalLess(a, b); }
};

}  // namespace calibench
