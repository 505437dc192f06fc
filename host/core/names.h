// names.h — one table of names per enum. The command line, the window's panel, event scripts and
// JSON files (edits, saved states, job descriptions) read and write an option by the same words:
// an enum has one `NameTable` beside its declaration and every reader goes through it, so adding
// a value is one line and no reader keeps a list of strings of its own (or a silent default for
// a word it does not know).
#pragma once
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace obscura {

template <typename E> struct Named {
  std::string_view name;
  E value;
};

template <typename E, std::size_t N> using NameTable = std::array<Named<E>, N>;

// The name of `value` ("" for a value the table does not hold: a table covers its enum, which
// the tests of each table check).
template <typename E, std::size_t N> constexpr std::string_view nameOf(const NameTable<E, N>& table, E value) {
  for (const Named<E>& entry : table)
    if (entry.value == value) return entry.name;
  return {};
}

// The same as a string (JSON values, messages).
template <typename E, std::size_t N> std::string nameString(const NameTable<E, N>& table, E value) {
  return std::string(nameOf(table, value));
}

// The value named `name`, if the table has it (exact match: names are lower case, as typed).
template <typename E, std::size_t N>
constexpr std::optional<E> valueNamed(const NameTable<E, N>& table, std::string_view name) {
  for (const Named<E>& entry : table)
    if (entry.name == name) return entry.value;
  return std::nullopt;
}

// Every name, in the table's order (the order --help and the panel list them in).
template <typename E, std::size_t N> std::vector<std::string> namesOf(const NameTable<E, N>& table) {
  std::vector<std::string> names;
  for (const Named<E>& entry : table) names.emplace_back(entry.name);
  return names;
}

// "a, b or c": the names as a sentence, for error messages.
template <typename E, std::size_t N> std::string namesSentence(const NameTable<E, N>& table) {
  std::string text;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) text += i + 1 == N ? " or " : ", ";
    text += table[i].name;
  }
  return text;
}

} // namespace obscura
