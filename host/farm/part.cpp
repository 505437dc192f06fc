#include "farm/part.h"

#include <charconv>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "core/sha256.h"

namespace obscura::farm {
namespace {
namespace fs = std::filesystem;

// A whole unsigned number, all of `text`.
bool parseUint(std::string_view text, std::uint32_t& value) {
  if (text.empty()) return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// A glTF URI's percent escapes decoded (RFC 3986 §2.1): "my%20scene.bin" names "my scene.bin".
std::string decodeUri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    unsigned value = 0;
    if (uri[i] == '%' && i + 2 < uri.size() && std::from_chars(uri.data() + i + 1, uri.data() + i + 3, value, 16).ptr == uri.data() + i + 3) {
      out.push_back(static_cast<char>(value));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

template <class T> T field(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key)) throw InputError(fmt::format("{}: the part's description has no '{}'", file, key));
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(fmt::format("{}: the part's '{}' is malformed", file, key));
  }
}

} // namespace

SampleRange parseSampleRange(const std::string& text, const std::string& option) {
  const auto colon = text.find(':');
  SampleRange range;
  if (colon == std::string::npos || !parseUint(std::string_view(text).substr(0, colon), range.begin) ||
      !parseUint(std::string_view(text).substr(colon + 1), range.end))
    throw InputError(fmt::format("{} {}: expected A:B, samples A (included) to B (excluded), e.g. 0:64", option, text));
  if (range.begin >= range.end)
    throw InputError(fmt::format("{} {}: the range is empty (A must be below B)", option, text));
  return range;
}

Tile parseTile(const std::string& text, const std::string& option) {
  const auto slash = text.find('/');
  Tile tile;
  if (slash == std::string::npos || !parseUint(std::string_view(text).substr(0, slash), tile.index) ||
      !parseUint(std::string_view(text).substr(slash + 1), tile.count))
    throw InputError(fmt::format("{} {}: expected I/T, tile I (0-based) of T, e.g. 3/16", option, text));
  if (tile.count == 0 || tile.index >= tile.count)
    throw InputError(fmt::format("{} {}: the tile index must be in 0..{}", option, text,
                                 tile.count == 0 ? 0 : tile.count - 1));
  return tile;
}

render::RowRange tileRows(const Tile& tile, std::uint32_t height) {
  if (tile.count > height)
    throw InputError(fmt::format("--tile {}/{}: an image of {} rows has fewer rows than tiles", tile.index, tile.count,
                                 height));
  const auto rowAt = [&](std::uint32_t i) { return static_cast<std::uint32_t>(std::uint64_t(i) * height / tile.count); };
  return {.first = rowAt(tile.index), .count = rowAt(tile.index + 1) - rowAt(tile.index)};
}

void writePart(const std::string& path, const Part& part) {
  io::Image image = part.sums;
  const nlohmann::json description = {
      {"version", kPartVersion},
      {"job", part.job},
      {"frame", part.frame},
      {"info", part.info},
      {"samples", {part.samples.begin, part.samples.end}},
      {"tile", {part.tile.index, part.tile.count}},
      {"rows", {part.rows.first, part.rows.count}}};
  image.attributes.emplace_back(kPartAttribute, description.dump());
  io::writeExr(path, image);
}

Part readPart(const std::string& path) {
  if (!fs::is_regular_file(path)) throw InputError(fmt::format("{}: no such part file", path));
  io::Image image = io::readImage(path);
  const std::string* text = image.attribute(kPartAttribute);
  if (!text)
    throw InputError(fmt::format("{}: not a part of a farm render (no {} attribute; parts are written by "
                                 "'obscura render --samples A:B' or '--tile I/T')", path, kPartAttribute));
  nlohmann::json d;
  try {
    d = nlohmann::json::parse(*text);
  } catch (const nlohmann::json::exception&) {
    throw InputError(fmt::format("{}: the part's description is not valid JSON", path));
  }
  if (!d.is_object() || !d.contains("version") || d["version"] != kPartVersion)
    throw InputError(fmt::format("{}: a part of version {} (this obscura reads version {}); render it again", path,
                                 d.is_object() && d.contains("version") ? d["version"].dump() : "unknown", kPartVersion));
  Part part;
  part.job = field<nlohmann::json>(d, "job", path);
  part.frame = field<nlohmann::json>(d, "frame", path);
  part.info = field<nlohmann::json>(d, "info", path);
  const auto samples = field<std::vector<std::uint32_t>>(d, "samples", path);
  const auto tile = field<std::vector<std::uint32_t>>(d, "tile", path);
  const auto rows = field<std::vector<std::uint32_t>>(d, "rows", path);
  if (samples.size() != 2 || tile.size() != 2 || rows.size() != 2)
    throw InputError(fmt::format("{}: the part's samples, tile or rows are malformed", path));
  part.samples = {samples[0], samples[1]};
  part.tile = {tile[0], tile[1]};
  part.rows = {rows[0], rows[1]};
  const auto width = field<std::uint32_t>(part.job, "width", path), height = field<std::uint32_t>(part.job, "height", path);
  const auto spp = field<std::uint32_t>(part.job, "spp", path);
  if (part.samples.begin >= part.samples.end || part.samples.end > spp)
    throw InputError(fmt::format("{}: samples {}:{} are not inside the job's {} samples", path, part.samples.begin,
                                 part.samples.end, spp));
  if (part.tile.count == 0 || part.tile.index >= part.tile.count || part.tile.count > height)
    throw InputError(fmt::format("{}: tile {}/{} is malformed", path, part.tile.index, part.tile.count));
  const render::RowRange expected = tileRows(part.tile, height);
  if (part.rows.first != expected.first || part.rows.count != expected.count)
    throw InputError(fmt::format("{}: rows {}+{} are not those of tile {}/{}", path, part.rows.first, part.rows.count,
                                 part.tile.index, part.tile.count));
  if (image.width != static_cast<int>(width) || image.height != static_cast<int>(part.rows.count))
    throw InputError(fmt::format("{}: {}x{} pixels, but tile {}/{} of a {}x{} job has {}x{}", path, image.width,
                                 image.height, part.tile.index, part.tile.count, width, height, width, part.rows.count));
  if (image.channelIndex("count") < 0) throw InputError(fmt::format("{}: the part has no 'count' channel", path));
  image.attributes.clear();
  part.sums = std::move(image);
  return part;
}

std::string sceneHash(const std::string& scenePath) {
  Sha256 hash;
  hash.update(sha256OfFile(scenePath));
  if (fs::path(scenePath).extension() != ".gltf") return hash.hexDigest();
  nlohmann::json gltf;
  {
    std::ifstream in(scenePath);
    try {
      gltf = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception&) {
      throw InputError(fmt::format("{}: not valid JSON", scenePath));
    }
  }
  for (const char* list : {"buffers", "images"}) {
    if (!gltf.contains(list) || !gltf[list].is_array()) continue;
    for (const auto& entry : gltf[list]) {
      if (!entry.is_object() || !entry.contains("uri") || !entry["uri"].is_string()) continue;
      const std::string uri = entry["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue; // embedded: in the file's own bytes
      const fs::path file = fs::path(scenePath).parent_path() / decodeUri(uri);
      hash.update(uri);
      hash.update(sha256OfFile(file.string()));
    }
  }
  return hash.hexDigest();
}

} // namespace obscura::farm
