// aov_render.h — one headless render of the primary pass: --spp samples per pixel accumulated
// into the AOV image (albedo, normal, depth, position, emission, ids, preview).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "io/image_io.h"
#include "scene/scene.h"

namespace obscura::render {

struct RenderSettings {
  std::uint32_t width = 512, height = 512;
  std::uint32_t spp = 4;
  std::uint32_t seed = 1;
  scene::Camera camera;
};

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
};

// Names of the AOVs this render produces, in the order of the EXR layers.
const std::vector<std::string>& aovNames();
// Channel names of one AOV ("albedo" -> albedo.R, albedo.G, albedo.B).
std::vector<std::string> aovChannels(const std::string& aov);

// Progress callback: samples done, samples total, seconds so far.
using ProgressFn = std::function<void(std::uint32_t, std::uint32_t, double)>;

// Renders all AOVs. The image holds every channel of every AOV.
io::Image renderAovs(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                     const RenderSettings& settings, RenderStats& stats,
                     const ProgressFn& progress = nullptr);

// The image of primary.comp's accumulated AOV slots (kAovSlots vec4 per pixel) after `spp` samples.
io::Image resolvePrimaryAovs(const std::vector<glm::vec4>& aov, std::uint32_t width, std::uint32_t height,
                             std::uint32_t spp);

// Device memory a render of this size needs beyond the scene.
std::uint64_t renderBytesNeeded(std::uint32_t width, std::uint32_t height);

} // namespace obscura::render
