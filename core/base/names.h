// Enums with names in files and on the command line: one table per enum, read both ways.
#pragma once

#include <optional>
#include <string>

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

}  // namespace calibench
