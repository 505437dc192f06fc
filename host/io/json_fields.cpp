// json_fields.cpp — see json_fields.h.
#include "io/json_fields.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::io {

using nlohmann::json;

void JsonEntry::fail(const std::string& what) const {
  throw InputError(fmt::format("{}: entry {}: {}", file, entry, what));
}

float jsonNumber(const json& j, const char* key, const JsonEntry& at) {
  if (!j.contains(key) || !j.at(key).is_number()) at.fail(fmt::format("'{}' must be a number", key));
  const float v = j.at(key).get<float>();
  if (!std::isfinite(v)) at.fail(fmt::format("'{}' must be finite", key));
  return v;
}

glm::vec3 jsonVec3(const json& j, const char* key, const JsonEntry& at) {
  if (!j.contains(key)) at.fail(fmt::format("'{}' is missing", key));
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }))
    at.fail(fmt::format("'{}' must be an array of 3 numbers", key));
  glm::vec3 out(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
  if (!std::isfinite(out.x) || !std::isfinite(out.y) || !std::isfinite(out.z))
    at.fail(fmt::format("'{}' must be finite", key));
  return out;
}

std::string jsonText(const json& j, const char* key, const JsonEntry& at) {
  if (!j.contains(key) || !j.at(key).is_string() || j.at(key).get<std::string>().empty())
    at.fail(fmt::format("'{}' must be a non-empty string", key));
  return j.at(key).get<std::string>();
}

} // namespace obscura::io
