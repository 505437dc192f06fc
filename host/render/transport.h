// transport.h — a finished frame's per-pixel light transport on the host, resolved (divided by
// the sample count), and compose's C++ twin over it.
//
// Per light s (a light group or punctual light) at unit emission: D_s the direct light at the
// primary hit, M_s the emission the camera sees, S_s the direct light gathered along specular
// paths; and, shared by all lights, A = albedo x W_c (with W) and A^spec along specular paths. The
// image with emissions E_s is [SPEC §3, IVR eq. 4]
//   C = sum_s E_s (D_s + M_s + S_s + I_s) + I_a(E) (A + A^spec),   I_a(E) = sum_s E_s w_s  [RTO eq. 12]
// so it is what relighting keeps (`obscura render --save-state`) and recomposes without a ray.
// I_s, a light's own indirect light, is there only where it was measured rather than modelled: a
// photographed room's, from its photographs (`obscura recover`), whose lights then have w_s = 0.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "io/image_io.h"

namespace obscura::render {

struct Transport {
  int width = 0, height = 0;
  std::vector<std::string> lights;               // names, in light order
  bool specular = false;                         // S_s and A^spec present
  std::vector<std::vector<glm::vec3>> direct;    // [light][pixel] D_s
  std::vector<std::vector<glm::vec3>> seen;      // [light][pixel] M_s
  std::vector<std::vector<glm::vec3>> specularDirect; // [light][pixel] S_s (when specular)
  std::vector<std::vector<glm::vec3>> ownIndirect;    // [light][pixel] I_s, or empty (none measured)
  std::vector<glm::vec4> ambient;                // [pixel] A rgb, W in w
  std::vector<glm::vec3> specularAmbient;        // [pixel] A^spec (when specular)

  std::size_t pixels() const { return std::size_t(width) * height; }

  bool hasOwnIndirect() const { return !ownIndirect.empty(); }

  // As EXR channels: "D.<light>.R/G/B", "M.<light>.…", "S.<light>.…", "I.<light>.…", "A.R/G/B",
  // "A.W", "SA.R/G/B".
  io::Image toImage() const;
  // From such channels (I_s when the first light has them); InputError naming `file` and the
  // missing channel when one is absent.
  static Transport fromImage(const io::Image& image, const std::vector<std::string>& lights, bool specular,
                             const std::string& file);
};

// Sums over samples (`sums`, each pixel's over counts[pixel] samples) divided by their counts as
// compose.comp divides them (by max(count, 1), as a float reciprocal): a frame's resolved
// transport, whether its sums come from one renderer or from a farm's merged parts.
Transport resolveSums(Transport sums, const std::vector<std::uint32_t>& counts);

// compose.comp's C++ twin: the AOVs combined, direct, indirect, specular, obscurance, emission
// (obscuranceAovNames' first five plus emission) with emissions E_s and I_a = sum_s E_s w_s;
// indirect holds sum_s E_s I_s too.
io::Image composeTransport(const Transport& transport, const std::vector<glm::vec3>& emissions,
                           const std::vector<glm::vec3>& ambientWeights);

// One RGB layer per light, "light.<name>.R/G/B" = E_s (D_s + M_s + S_s + I_s + w_s (A + A^spec)): each
// light's whole contribution, its share of the indirect term included, so they sum to combined.
io::Image lightLayers(const Transport& transport, const std::vector<glm::vec3>& emissions,
                      const std::vector<glm::vec3>& ambientWeights);

} // namespace obscura::render
