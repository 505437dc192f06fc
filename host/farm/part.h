// part.h — a render cut into parts that a render farm runs as separate tasks (a Slurm array's
// tasks, a Kubernetes Indexed Job's pods; tools/farm/), merged exactly by `obscura merge`.
//
// A part is a sample range [A, B) of the frame's N samples (`render --samples A:B`), a tile (the
// I-th of T strips of whole rows, `render --tile I/T`), or both. It renders those samples with the
// sample sequence one process uses for the same indices (seeds and sub-pixel positions are
// functions of the pixel and the sample index), so the parts of a frame hold exactly the samples
// of the whole frame. A part keeps sums and per-pixel sample counts, never means, and the job's
// identity (scene hash, settings, seed), so that merging is a sum and a foreign part is refused.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "render/frame/frame_layout.h"

namespace obscura::farm {

// Samples [begin, end) of the frame's sequence.
struct SampleRange {
  std::uint32_t begin = 0, end = 0;
  std::uint32_t count() const { return end - begin; }
  bool overlaps(const SampleRange& o) const { return begin < o.end && o.begin < end; }
  bool operator==(const SampleRange&) const = default;
};

// The `index`-th (0-based) of `count` strips of whole rows that cover the image.
struct Tile {
  std::uint32_t index = 0, count = 1;
  bool operator==(const Tile&) const = default;
};

// "A:B" (0 <= A < B); InputError naming `option` otherwise.
SampleRange parseSampleRange(const std::string& text, const std::string& option = "--samples");
// "I/T" (0 <= I < T); InputError naming `option` otherwise.
Tile parseTile(const std::string& text, const std::string& option = "--tile");
// The rows of tile `tile` of an image `height` rows high: [floor(I H / T), floor((I + 1) H / T)),
// balanced; InputError when a tile would have no row (T > H).
render::RowRange tileRows(const Tile& tile, std::uint32_t height);

// One part as written: the job it belongs to, which part it is, and its sums.
struct Part {
  // What identifies the job; every part of a job carries the same (merge compares it exactly):
  // method, size, spp, seed, every setting that changes a pixel, the scene's SHA-256.
  nlohmann::json job;
  // What the renderer derived from the scene for the whole frame (lights, their render-time
  // emissions and I_a weights, whether specular paths ran): the same in every part; merge checks
  // the names exactly and the numbers to 1e-5.
  nlohmann::json frame;
  // Where and how it was made (scene path, device, GPU ms, wall s): informational.
  nlohmann::json info;
  SampleRange samples;
  Tile tile;
  render::RowRange rows; // tileRows(tile, height)
  // width x rows.count pixels: "count" (samples summed, as float: exact below 2^24), then the
  // method's sums (partChannels).
  io::Image sums;
};

// The EXR attribute that holds a part's description (JSON), and the one a merged frame carries.
inline constexpr const char* kPartAttribute = "obscura:part";
inline constexpr const char* kMergedAttribute = "obscura:job";
inline constexpr int kPartVersion = 1;

// Writes `part` as an EXR (sums as float channels, its description as kPartAttribute),
// atomically: a temporary file renamed, so a killed task leaves no part that merge could take.
void writePart(const std::string& path, const Part& part);
// Reads a part; InputError naming the file when it is not a part this obscura wrote (no or a
// malformed description, another version, channels missing, a size that does not match).
Part readPart(const std::string& path);

// The SHA-256 of a scene: its file and, for .gltf, every file it names by a relative URI (buffers,
// images), in the order named. InputError naming the file that cannot be read.
std::string sceneHash(const std::string& scenePath);

} // namespace obscura::farm
