// json_fields.h — typed fields of one entry of a JSON list a user wrote (an edits file, a view
// script), with errors that name the file, the entry and the field.
#pragma once
#include <cstddef>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/names.h"

namespace obscura::io {

struct JsonEntry {
  const std::string& file;
  std::size_t entry;
  // InputError "<file>: entry <n>: <what>".
  [[noreturn]] void fail(const std::string& what) const;
};

// A finite number at `key`.
float jsonNumber(const nlohmann::json& j, const char* key, const JsonEntry& at);
// An array of 3 finite numbers at `key`.
glm::vec3 jsonVec3(const nlohmann::json& j, const char* key, const JsonEntry& at);
// A non-empty string at `key`.
std::string jsonText(const nlohmann::json& j, const char* key, const JsonEntry& at);
// One of `table`'s names at `key` ("'<key>' is a, b or c" otherwise), as its value.
template <typename E, std::size_t N>
E jsonNamed(const nlohmann::json& j, const char* key, const NameTable<E, N>& table, const JsonEntry& at) {
  const std::string name = jsonText(j, key, at);
  if (const auto value = valueNamed(table, name)) return *value;
  at.fail("'" + std::string(key) + "' is " + namesSentence(table));
}

} // namespace obscura::io
