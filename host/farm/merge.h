// merge.h — a farm's parts summed into one frame (`obscura merge`), refusing what would not
// give the frame one process renders: parts of another job, parts that overlap, or a set that
// misses samples of some rows (unless a preview is asked for).
//
// Exactness: each pixel's sums are added over the parts that hold it in double precision and
// rounded to float once. A pixel held by one part (a frame split only into tiles, or one part)
// keeps that part's float sums bit for bit, and the merged image is then bit-identical to one
// process's (the same sums resolved by the same code). Sample ranges split a pixel's Kahan sum
// into several (the GPU's running sum restarts at each part's first sample): the merged sum then
// differs from one process's by float rounding (a few ulps), not by any sample.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farm/part.h"
#include "io/image_io.h"
#include "render/method.h"
#include "render/transport.h"

namespace obscura::farm {

// Samples of some rows that no part holds.
struct MissingPiece {
  render::RowRange rows;
  SampleRange samples;
  Tile tile;          // the tile those rows are, when they are one of the parts' tiling
  bool isTile = false;
  // "tile 2/4 samples 0:16" (or "rows 10..20 samples 0:16").
  std::string describe() const;
  // The render options that make it: "--tile 2/4 --samples 0:16" (rows that are no tile: "").
  std::string renderArguments() const;
};

struct MergedFrame {
  nlohmann::json job, frame;
  nlohmann::json info;                 // the first part's (where the scene lay, its device)
  std::vector<std::string> files;      // the parts merged, in the order read
  std::vector<MissingPiece> missing;   // empty when the parts cover every row and sample
  // width x height: "count" and the method's sums, as the parts name them; 0 where missing.
  io::Image sums;
  double partGpuMs = 0.0, partWallSeconds = 0.0; // the parts' own figures, summed

  std::uint32_t spp() const { return job.at("spp").get<std::uint32_t>(); }
  // The job's method (InputError naming the first part for a name render::kMethodNames lacks).
  render::Method method() const;
};

// The part files named: files as given, folders as the .exr files in them (sorted; hidden ones,
// such as a killed render's temporary file, left out). InputError
// when a name is neither, or nothing is found.
std::vector<std::string> partFiles(const std::vector<std::string>& names);

// Reads and checks the parts (same job, no overlap) and sums them. Missing pieces are listed in
// the result; whether they are an error is the caller's choice (merge's --partial).
MergedFrame mergeParts(const std::vector<std::string>& files);

// What a merged frame is, as the image `render -o out.exr` writes for the same job: the
// obscurance method's composed AOVs, primary AOVs and light layers (composed on the host, by
// compose.comp's C++ twin), or path tracing's combined.
io::Image mergedImage(const MergedFrame& merged);
// The obscurance method's resolved per-light transport (what `relight DIR` reads).
render::Transport mergedTransport(const MergedFrame& merged);
// state.json for `relight DIR` (obscurance method only).
nlohmann::json mergedStateJson(const MergedFrame& merged);

} // namespace obscura::farm
