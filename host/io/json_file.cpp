#include "io/json_file.h"

#include <fstream>

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::io {

nlohmann::json readJsonFile(const std::string& path, const std::string& missing) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: {}", path, missing));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({})", path, e.what()));
  }
}

} // namespace obscura::io
