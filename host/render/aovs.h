// aovs.h — the names, channels and resolution of the AOVs every renderer writes, and the figures
// a render reports (RenderStats).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "io/image_io.h"

namespace obscura::render {

struct PassStats {
  double gpuMs = 0.0;       // GPU timestamps, summed over samples
  std::uint64_t rays = 0;   // rays traced by the pass
};

struct RenderStats {
  std::map<std::string, PassStats> passes;
  double wallSeconds = 0.0;
  std::uint32_t truncatedTraversals = 0; // must be 0; reported so it can never go unnoticed
  std::uint64_t deviceBytes = 0;
  std::vector<std::string> notes;        // what the upload changed (e.g. textures reduced)

  double totalGpuMs() const {
    double ms = 0.0;
    for (const auto& [name, pass] : passes) ms += pass.gpuMs;
    return ms;
  }
  std::uint64_t totalRays() const {
    std::uint64_t rays = 0;
    for (const auto& [name, pass] : passes) rays += pass.rays;
    return rays;
  }
};

// Names of the primary pass's AOVs, in the order of the EXR layers.
const std::vector<std::string>& aovNames();
// Channel names of one AOV ("albedo" -> albedo.R, albedo.G, albedo.B).
std::vector<std::string> aovChannels(const std::string& aov);
// Only the channels of `aovs`, in that order (all of `image` when empty), its attributes kept;
// InputError naming an AOV the image lacks.
io::Image selectAovs(const io::Image& image, const std::vector<std::string>& aovs);

// Progressive samples recorded into one submission by the renderers: each pass of a sample takes
// one timestamp pair of a 256-pair pool, and fewer per submission keep the progress line moving.
inline constexpr std::uint32_t kSamplesPerSubmission = 16;

// Progress callback: samples done, samples total, seconds so far.
using ProgressFn = std::function<void(std::uint32_t, std::uint32_t, double)>;

// The image of primary.comp's accumulated AOV slots (kAovSlots Kahan pairs per pixel), for `rows`
// rows of `width` pixels, pixel p holding `samples[p]` samples.
io::Image resolvePrimaryAovs(const std::vector<glm::vec4>& aov, std::uint32_t width, std::uint32_t rows,
                             const std::vector<std::uint32_t>& samples);

} // namespace obscura::render
