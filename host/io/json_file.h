// json_file.h — reading a JSON file a user wrote or obscura saved, with errors that name it.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

namespace obscura::io {

// The parsed file. InputError "<path>: <missing>" when it cannot be read, "<path>: not valid JSON
// (...)" when it does not parse. `missing` says what the file should have been.
nlohmann::json readJsonFile(const std::string& path, const std::string& missing);

} // namespace obscura::io
