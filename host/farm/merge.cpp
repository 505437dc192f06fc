#include "farm/merge.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "core/error.h"
#include "render/aovs.h"
#include "shared/host_device.h"

namespace obscura::farm {
namespace {
namespace fs = std::filesystem;

// The first key whose value differs between two job descriptions (for the refusal's message).
std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& prefix = "") {
  std::set<std::string> keys;
  for (const auto& [k, v] : a.items()) keys.insert(k);
  for (const auto& [k, v] : b.items()) keys.insert(k);
  for (const auto& k : keys) {
    const nlohmann::json va = a.contains(k) ? a.at(k) : nlohmann::json("(none)");
    const nlohmann::json vb = b.contains(k) ? b.at(k) : nlohmann::json("(none)");
    if (va == vb) continue;
    if (va.is_object() && vb.is_object()) return firstDifference(va, vb, prefix + k + ".");
    return fmt::format("{}{} is {} there and {} here", prefix, k, vb.dump(), va.dump());
  }
  return "";
}

bool near(float a, float b) { return std::abs(a - b) <= 1e-5f * std::max(std::abs(a), std::abs(b)) + 1e-20f; }

// The frame each part derived from the scene must be the same: the lights by name and type
// exactly, their emissions and I_a weights to 1e-5 (the CPU measurement of what each light
// reaches runs on threads; a part on another machine may round differently).
void checkSameFrame(const nlohmann::json& mine, const nlohmann::json& first, const std::string& file,
                    const std::string& firstFile) {
  auto numbersNear = [](const nlohmann::json& a, const nlohmann::json& b, auto&& self) -> bool {
    if (a.is_number() && b.is_number()) return near(a.get<float>(), b.get<float>());
    if (a.is_array() && b.is_array()) {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i)
        if (!self(a[i], b[i], self)) return false;
      return true;
    }
    if (a.is_object() && b.is_object()) {
      if (a.size() != b.size()) return false;
      for (const auto& [k, v] : a.items())
        if (!b.contains(k) || !self(v, b.at(k), self)) return false;
      return true;
    }
    return a == b;
  };
  if (!numbersNear(mine, first, numbersNear))
    throw InputError(fmt::format("{}: its renderer derived another frame from the scene than {} did ({}); were they "
                                 "rendered by different versions of obscura?",
                                 file, firstFile, firstDifference(mine, first)));
}

struct PartExtent {
  std::string file;
  SampleRange samples;
  render::RowRange rows;
  Tile tile;
};

// Rows [first, first + count) as text.
std::string rowsText(const render::RowRange& r) { return fmt::format("rows {}..{}", r.first, r.first + r.count); }

// The samples of [0, spp) no part holds, for every stretch of rows the parts' edges cut.
std::vector<MissingPiece> findMissing(const std::vector<PartExtent>& parts, std::uint32_t height, std::uint32_t spp) {
  std::set<std::uint32_t> edges = {0, height};
  std::set<std::uint32_t> tilings;
  for (const auto& p : parts) {
    edges.insert(p.rows.first);
    edges.insert(p.rows.first + p.rows.count);
    tilings.insert(p.tile.count);
  }
  std::vector<MissingPiece> missing;
  for (auto it = edges.begin(); std::next(it) != edges.end(); ++it) {
    const render::RowRange rows{.first = *it, .count = *std::next(it) - *it};
    std::vector<SampleRange> held;
    for (const auto& p : parts)
      if (p.rows.first <= rows.first && rows.first + rows.count <= p.rows.first + p.rows.count) held.push_back(p.samples);
    std::sort(held.begin(), held.end(), [](const auto& a, const auto& b) { return a.begin < b.begin; });
    std::vector<SampleRange> gaps;
    std::uint32_t next = 0;
    for (const auto& h : held) {
      if (h.begin > next) gaps.push_back({next, h.begin});
      next = std::max(next, h.end);
    }
    if (next < spp) gaps.push_back({next, spp});
    for (const auto& gap : gaps) {
      MissingPiece piece{.rows = rows, .samples = gap};
      // Name the rows as a tile where they are one of the tilings the parts use.
      for (std::uint32_t count : tilings)
        for (std::uint32_t i = 0; i < count && !piece.isTile; ++i) {
          const render::RowRange r = tileRows({i, count}, height);
          if (r.first == rows.first && r.count == rows.count) piece.tile = {i, count}, piece.isTile = true;
        }
      missing.push_back(piece);
    }
  }
  return missing;
}

std::vector<glm::vec3> lightVectors(const nlohmann::json& frame, const char* key) {
  std::vector<glm::vec3> out;
  for (const auto& light : frame.at("state").at("lights")) {
    const auto v = light.at(key).get<std::vector<float>>();
    out.emplace_back(v.at(0), v.at(1), v.at(2));
  }
  return out;
}

std::vector<std::uint32_t> countsOf(const io::Image& sums) {
  const int c = sums.channelIndex("count");
  std::vector<std::uint32_t> counts(std::size_t(sums.width) * sums.height);
  for (std::size_t p = 0; p < counts.size(); ++p)
    counts[p] = static_cast<std::uint32_t>(sums.pixels[p * sums.channels.size() + c]);
  return counts;
}

// The primary AOV slots' sums a part names "P<slot>.X/Y/Z/W".
std::string primarySlotChannel(std::uint32_t slot, int component) {
  return fmt::format("P{}.{}", slot, "XYZW"[component]);
}

} // namespace

std::string MissingPiece::describe() const {
  return fmt::format("{} samples {}:{}", isTile ? fmt::format("tile {}/{}", tile.index, tile.count) : rowsText(rows),
                     samples.begin, samples.end);
}

std::string MissingPiece::renderArguments() const {
  if (!isTile) return "";
  return fmt::format("--tile {}/{} --samples {}:{}", tile.index, tile.count, samples.begin, samples.end);
}

std::vector<std::string> partFiles(const std::vector<std::string>& names) {
  std::vector<std::string> files;
  for (const auto& name : names) {
    if (fs::is_directory(name)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::directory_iterator(name))
        // Hidden files are left out: a render killed while writing leaves its temporary file
        // (".NAME.tmpPID.exr", io/image_io.cpp's atomic write) beside the parts.
        if (entry.is_regular_file() && io::extensionOf(entry.path().string()) == "exr" &&
            entry.path().filename().string().front() != '.')
          found.push_back(entry.path().string());
      if (found.empty()) throw InputError(fmt::format("{}: the folder holds no .exr part", name));
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(name)) {
      files.push_back(name);
    } else {
      throw InputError(fmt::format("{}: no such part file or folder", name));
    }
  }
  if (files.empty()) throw InputError("merge: no part given");
  return files;
}

MergedFrame mergeParts(const std::vector<std::string>& files) {
  MergedFrame merged;
  std::vector<PartExtent> extents;
  // The merged sums are merged.sums (float); a row that a second part adds to is summed in double
  // (doubleRows[y]) and rounded once at the end.
  std::vector<std::vector<double>> doubleRows;
  std::vector<std::uint32_t> partsOfRow;
  std::vector<std::uint32_t> idsFromSample; // per row: the first sample of the part its ids came from
  std::vector<bool> firstSampleOnly;        // per channel: written by a part's first sample, not summed
  std::uint32_t width = 0, height = 0;
  for (const auto& file : files) {
    Part part = readPart(file);
    if (merged.files.empty()) {
      merged.job = part.job;
      merged.frame = part.frame;
      merged.info = part.info;
      width = part.job.at("width").get<std::uint32_t>();
      height = part.job.at("height").get<std::uint32_t>();
      merged.sums.width = static_cast<int>(width);
      merged.sums.height = static_cast<int>(height);
      merged.sums.channels = part.sums.channels;
      merged.sums.pixels.resize(std::size_t(width) * height * part.sums.channels.size());
      doubleRows.resize(height);
      partsOfRow.assign(height, 0);
      idsFromSample.assign(height, std::numeric_limits<std::uint32_t>::max());
      for (const auto& c : part.sums.channels) firstSampleOnly.push_back(c.rfind(fmt::format("P{}.", gpu::kAovIds), 0) == 0);
    } else {
      if (part.job != merged.job)
        throw InputError(fmt::format("{}: a part of another job than {} ({})", file, merged.files.front(),
                                     firstDifference(part.job, merged.job)));
      checkSameFrame(part.frame, merged.frame, file, merged.files.front());
      if (part.sums.channels != merged.sums.channels)
        throw InputError(fmt::format("{}: its channels are not those of {}", file, merged.files.front()));
    }
    for (const auto& other : extents) {
      const bool rowsOverlap = part.rows.first < other.rows.first + other.rows.count &&
                               other.rows.first < part.rows.first + part.rows.count;
      if (rowsOverlap && part.samples.overlaps(other.samples))
        throw InputError(fmt::format("{}: overlaps {}: both hold samples {}:{} of rows {}..{}; merge each sample of "
                                     "each pixel once (remove one of them)",
                                     file, other.file, std::max(part.samples.begin, other.samples.begin),
                                     std::min(part.samples.end, other.samples.end),
                                     std::max(part.rows.first, other.rows.first),
                                     std::min(part.rows.first + part.rows.count, other.rows.first + other.rows.count)));
    }
    const std::size_t nc = part.sums.channels.size(), rowValues = std::size_t(width) * nc;
    for (std::uint32_t row = 0; row < part.rows.count; ++row) {
      const std::uint32_t y = part.rows.first + row;
      const float* in = &part.sums.pixels[row * rowValues];
      float* merged_ = &merged.sums.pixels[y * rowValues];
      const bool takeIds = part.samples.begin < idsFromSample[y];
      if (partsOfRow[y]++ == 0) {
        // The row's first part: its float sums as they are (a row one part holds stays bit-exact).
        std::copy_n(in, rowValues, merged_);
      } else {
        // A second part of the row: its sums are added in double from here on.
        std::vector<double>& acc = doubleRows[y];
        if (acc.empty()) acc.assign(merged_, merged_ + rowValues);
        for (std::size_t i = 0; i < rowValues; ++i) {
          const std::size_t c = i % nc;
          if (!firstSampleOnly[c]) acc[i] += static_cast<double>(in[i]);
          else if (takeIds) merged_[i] = in[i];
        }
      }
      if (takeIds) idsFromSample[y] = part.samples.begin;
    }
    extents.push_back({file, part.samples, part.rows, part.tile});
    merged.files.push_back(file);
    if (part.info.contains("gpu_ms")) merged.partGpuMs += part.info.at("gpu_ms").get<double>();
    if (part.info.contains("wall_s")) merged.partWallSeconds += part.info.at("wall_s").get<double>();
  }
  merged.missing = findMissing(extents, height, merged.spp());
  // Rows summed in double are rounded to float once; the ids (bit patterns, uintBitsToFloat) were
  // copied from the part with the row's first sample, never summed.
  const std::size_t rowValues = std::size_t(width) * merged.sums.channels.size();
  for (std::uint32_t y = 0; y < height; ++y) {
    if (doubleRows[y].empty()) continue;
    float* out = &merged.sums.pixels[y * rowValues];
    for (std::size_t i = 0; i < rowValues; ++i)
      if (!firstSampleOnly[i % merged.sums.channels.size()]) out[i] = static_cast<float>(doubleRows[y][i]);
  }
  return merged;
}

namespace {

// The merged per-light transport, resolved by the pixels' sample counts `counts`.
render::Transport resolvedTransport(const MergedFrame& merged, const std::vector<std::uint32_t>& counts) {
  if (merged.method() != render::Method::Obscurance) throw InputError("merge: only the obscurance method keeps per-light transport");
  const nlohmann::json& state = merged.frame.at("state");
  std::vector<std::string> names;
  for (const auto& light : state.at("lights")) names.push_back(light.at("name").get<std::string>());
  render::Transport sums = render::Transport::fromImage(merged.sums, names, state.at("specular").get<bool>(),
                                                        merged.files.front());
  return render::resolveSums(std::move(sums), counts);
}

} // namespace

render::Transport mergedTransport(const MergedFrame& merged) { return resolvedTransport(merged, countsOf(merged.sums)); }

nlohmann::json mergedStateJson(const MergedFrame& merged) {
  nlohmann::json state = merged.frame.at("state");
  state["samples"] = merged.spp();
  state["scene"] = merged.info.value("scene_path", "");
  return state;
}

io::Image mergedImage(const MergedFrame& merged) {
  const std::vector<std::uint32_t> counts = countsOf(merged.sums);
  io::Image image;
  if (merged.method() == render::Method::PathTrace) {
    // PathTracer::image(): the sums times the reciprocal of the samples.
    image.width = merged.sums.width;
    image.height = merged.sums.height;
    image.channels = render::aovChannels("combined");
    const int c = merged.sums.channelIndex("combined.R");
    const std::size_t nc = merged.sums.channels.size();
    image.pixels.resize(counts.size() * 3);
    for (std::size_t p = 0; p < counts.size(); ++p) {
      const float inv = 1.0f / static_cast<float>(std::max(counts[p], 1u));
      for (int k = 0; k < 3; ++k) image.pixels[p * 3 + k] = merged.sums.pixels[p * nc + c + k] * inv;
    }
    image.attributes.emplace_back(kMergedAttribute, merged.job.dump());
    return image;
  }
  const render::Transport transport = resolvedTransport(merged, counts);
  const std::vector<glm::vec3> emissions = lightVectors(merged.frame, "emission");
  const std::vector<glm::vec3> weights = lightVectors(merged.frame, "ambient_weight");
  const io::Image composed = render::composeTransport(transport, emissions, weights);
  const bool primary = merged.frame.at("primary_aovs").get<bool>();
  // The renderer's order (ObscuranceRenderer::image): the composed AOVs, then the primary pass's,
  // whose emission is the composed one; then one layer per light.
  image.width = composed.width;
  image.height = composed.height;
  std::vector<int> composedChannels;
  for (int c = 0; c < composed.channelCount(); ++c)
    if (!primary || composed.channels[c].rfind("emission.", 0) != 0) composedChannels.push_back(c);
  for (int c : composedChannels) image.channels.push_back(composed.channels[c]);
  io::Image primaryAovs;
  if (primary) {
    const std::size_t nc = merged.sums.channels.size();
    std::vector<int> slotChannel(gpu::kAovSlots * 4);
    for (std::uint32_t slot = 0; slot < gpu::kAovSlots; ++slot)
      for (int k = 0; k < 4; ++k) {
        slotChannel[slot * 4 + k] = merged.sums.channelIndex(primarySlotChannel(slot, k));
        if (slotChannel[slot * 4 + k] < 0)
          throw InputError(fmt::format("{}: no channel {}", merged.files.front(), primarySlotChannel(slot, k)));
      }
    // resolvePrimaryAovs reads Kahan pairs: the sums, with a zero compensation beside each.
    std::vector<glm::vec4> pairs(counts.size() * gpu::kAovSlots * gpu::kAccumulatorVec4s, glm::vec4(0.0f));
    for (std::size_t p = 0; p < counts.size(); ++p)
      for (std::uint32_t slot = 0; slot < gpu::kAovSlots; ++slot)
        for (int k = 0; k < 4; ++k)
          pairs[(p * gpu::kAovSlots + slot) * gpu::kAccumulatorVec4s][k] = merged.sums.pixels[p * nc + slotChannel[slot * 4 + k]];
    primaryAovs = render::resolvePrimaryAovs(pairs, static_cast<std::uint32_t>(merged.sums.width),
                                             static_cast<std::uint32_t>(merged.sums.height), counts);
    image.channels.insert(image.channels.end(), primaryAovs.channels.begin(), primaryAovs.channels.end());
  }
  const std::size_t nc = image.channels.size();
  image.pixels.resize(counts.size() * nc);
  const int emissionIn = composed.channelIndex("emission.R"), emissionOut = image.channelIndex("emission.R");
  for (std::size_t p = 0; p < counts.size(); ++p) {
    float* out = &image.pixels[p * nc];
    std::size_t k = 0;
    for (int c : composedChannels) out[k++] = composed.pixels[p * composed.channels.size() + c];
    if (!primary) continue;
    std::copy_n(&primaryAovs.pixels[p * primaryAovs.channels.size()], primaryAovs.channels.size(), out + k);
    for (int c = 0; c < 3; ++c) out[emissionOut + c] = composed.pixels[p * composed.channels.size() + emissionIn + c];
  }
  io::appendChannels(image, render::lightLayers(transport, emissions, weights));
  image.attributes.emplace_back(kMergedAttribute, merged.job.dump());
  return image;
}

render::Method MergedFrame::method() const {
  const std::string name = job.at("method").get<std::string>();
  if (const auto method = valueNamed(render::kMethodNames, name)) return *method;
  throw InputError(fmt::format("{}: its job's method \"{}\" is not {}", files.empty() ? "merge" : files.front(), name,
                               namesSentence(render::kMethodNames)));
}

} // namespace obscura::farm
