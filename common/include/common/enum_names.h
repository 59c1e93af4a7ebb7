// common/enum_names.h: one table of names per enum, and the lookups every module uses on it,
// so that printing and parsing cannot drift apart and every out-of-range value prints the same
// "unknown".
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace common {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

// The name of `value`, or "unknown" for a value the table lacks (an out-of-range cast).
template <class E>
const char* enum_name(std::span<const EnumName<E>> table, E value) {
  for (const EnumName<E>& entry : table)
    if (entry.value == value) return entry.name;
  return "unknown";
}

template <class E>
std::vector<std::string> enum_names(std::span<const EnumName<E>> table) {
  std::vector<std::string> names;
  for (const EnumName<E>& entry : table) names.emplace_back(entry.name);
  return names;
}

// "a, b or c", for messages.
template <class E>
std::string enum_name_list(std::span<const EnumName<E>> table) {
  std::string list;
  for (std::size_t i = 0; i < table.size(); ++i)
    list += (i == 0 ? "" : i + 1 == table.size() ? " or " : ", ") + std::string(table[i].name);
  return list;
}

// Throws std::invalid_argument "unknown <what> '<name>'; use a, b or c".
template <class E>
E parse_enum(std::span<const EnumName<E>> table, const std::string& name, const char* what) {
  for (const EnumName<E>& entry : table)
    if (name == entry.name) return entry.value;
  throw std::invalid_argument("unknown " + std::string(what) + " '" + name + "'; use " +
                              enum_name_list(table));
}

// An enum's table with the word that names it in messages ("render mode"): each module
// exposes one per public enum, so printing, parsing and listing share one set of names.
template <class E, std::size_t N>
struct EnumTable {
  const char* what;
  std::array<EnumName<E>, N> entries;

  const char* name(E value) const { return enum_name<E>(entries, value); }
  E parse(const std::string& text) const { return parse_enum<E>(entries, text, what); }
  std::vector<std::string> names() const { return enum_names<E>(entries); }
  std::string list() const { return enum_name_list<E>(entries); }
};

// enum_table<Mode>("render mode", {{Mode::kA, "a"}, ...}): the entry count is deduced.
template <class E, std::size_t N>
constexpr EnumTable<E, N> enum_table(const char* what, const EnumName<E> (&entries)[N]) {
  EnumTable<E, N> table{what, {}};
  for (std::size_t i = 0; i < N; ++i) table.entries[i] = entries[i];
  return table;
}

}  // namespace common
