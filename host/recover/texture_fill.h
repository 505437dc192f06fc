// texture_fill.h — reflectance for pixels that were never photographed (a removed object
// uncovers the surfaces behind it), synthesized from the same surface where the photographs did
// see it [IVR §5: "texture masks" and "weight masks"; the paper used Heeger–Bergen synthesis].
//
// OURS: an exemplar (patch) fill with a smooth mean, chosen over Heeger–Bergen because the
// recovered reflectance of a real surface is a slowly varying mean (lighting errors, large-scale
// stains) plus fine texture and noise, and the two need different treatment at a seam:
//   R(p) = M(p) + D(p)
//   M   the surface's local mean: its 25x25 mean over the known pixels of the same surface, and
//       inside the hole the harmonic (Laplace) interpolation of that mean from the hole's border,
//       so the low frequencies continue across the seam with no step;
//   D   the finer texture: 16x16 tiles of the source's deviation from its own local mean, copied
//       from random places of the same surface that the photographs saw fully (the texture mask:
//       the source tiles), laid on a grid of step 4 and blended with raised-cosine weights
//       w = sin^2 x sin^2 that sum to 1 (the weight mask), divided by sqrt(sum w^2) so that the
//       blend keeps the source's variance instead of averaging it away at the overlaps.
// Exemplar tiles keep the source's own histogram and pixel-level structure (Heeger–Bergen matches
// a pyramid's histograms and needs an iterative pyramid for that) and need nothing beyond the
// standard library. A "surface" is one object and one plane: pixels of the object whose normals
// agree with the hole pixel's (dot > 0.95).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace obscura::recover {

struct TextureFillInput {
  int width = 0, height = 0;
  std::vector<glm::vec3> reflectance;  // known where `source` is set
  std::vector<std::int32_t> object;    // what each pixel sees (-1: nothing)
  std::vector<glm::vec3> normal;       // its normal
  std::vector<std::uint8_t> source;    // 1: a measured reflectance that may be copied
  std::vector<std::uint8_t> hole;      // 1: to synthesize
  std::uint32_t seed = 1;
};

struct TextureFillReport {
  std::size_t holePixels = 0;
  std::size_t tiles = 0;           // tiles laid over the holes
  std::size_t meanOnly = 0;        // hole pixels whose surface had no full source tile (mean only)
  std::size_t rimOnly = 0;         // hole pixels whose surface was photographed only along its rim (left as they were)
};

// `input.reflectance` with every hole pixel synthesized from its surface's source pixels (or,
// with no source pixel of its surface at all, or only ones within kRim of the source's edge,
// left as it was). The source's rim (kRim = 4 pixels) gives neither the mean nor the texture
// where the surface has pixels clear of it.
std::vector<glm::vec3> fillByTexture(const TextureFillInput& input, TextureFillReport* report = nullptr);

} // namespace obscura::recover
