// path_tracer.h — the reference renderer: unbiased path tracing [RTO §5.1, SPEC §1.5] with the
// same scene buffers, traversal, BSDF and light sampling as the obscurance passes
// (shaders/pathtrace.comp). Progressive: iteration i traces one path per pixel (sample i) and
// adds it to a per-pixel radiance sum; the image is the sum / spp.
#pragma once
#include <cstdint>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "io/image_io.h"
#include "gpu/command_stream.h"
#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "render/aovs.h"
#include "render/frame/frame_layout.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/light_tree.h"
#include "render/scene_data/scene_buffers.h"
#include "render/status_counters.h"
#include "scene/scene.h"

namespace obscura::render {

// Which techniques estimate the light of AREA emitters. Punctual lights are always sampled
// (nothing else can reach them) and emitters seen by the camera or through a mirror always
// count. Everything but Mis is for tests: all three converge to the same image.
enum class PathStrategy : std::uint32_t {
  Mis = 0,       // light sampling + BSDF sampling, power heuristic (Veach & Guibas 1995)
  LightOnly = 1, // next-event estimation only
  BsdfOnly = 2,  // emitters found by BSDF-sampled rays only
};

struct PathTraceSettings {
  std::uint32_t width = 512, height = 512;
  std::uint32_t spp = 64;          // paths per pixel (iterations)
  std::uint32_t seed = 1;
  scene::Camera camera;
  std::uint32_t maxDepth = 6;      // scattering vertices d [SPEC §5]: 1 = direct light only
  std::uint32_t rrDepth = 3;       // Russian roulette after this many vertices (>= maxDepth: never)
  PathStrategy strategy = PathStrategy::Mis;
  LightSampling lightSampling = LightSampling::Spatial; // next-event estimation's light sampling
  // Camera rays per path for the emission the camera sees, 1..64, and whether only where an
  // emitter's edge crosses the pixel (as ObscuranceSettings's).
  std::uint32_t emissionSamples = gpu::kEdgeEmissionSamples;
  bool emissionAtEdges = true;
  // A farm's part (host/farm/): paths from sample `firstSample` of the frame's sequence on, for
  // the rows `rows` of the width x height image only (as ObscuranceSettings's).
  std::uint32_t firstSample = 0;
  RowRange rows;
};

// The largest maxDepth accepted (each vertex costs loop passes of lavapipe's limiter; a deeper
// path is far past what Russian roulette lets through anyway).
inline constexpr std::uint32_t kMaxPathDepth = 1024;

// The path tracer, shaped like ObscuranceRenderer: made once per scene and view, progressive.
// Scene lifetime: SceneBuffers and the lights; frame lifetime: one radiance accumulator per band
// and the ray counters; its one pass is pathtrace.comp.
class PathTracer {
public:
  // Throws InputError for maxDepth > kMaxPathDepth, a zero-sized image or spp 0.
  PathTracer(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
             const PathTraceSettings& settings, std::uint64_t maxBufferBytes = 0);

  // New settings of the same resolution (seed, spp, depth, strategy, camera); restarts.
  void configure(const PathTraceSettings& settings);
  void reset();
  void iterate(std::uint32_t samples, const ProgressFn& progress = nullptr);
  // reset() + iterate(settings.spp).
  void render(const ProgressFn& progress = nullptr);

  // combined.R/G/B: the mean radiance per pixel so far.
  io::Image image() const;
  // combined.R/G/B: the radiance sums per pixel so far, not divided by samples() (a farm's part).
  io::Image sums() const;
  // Samples dropped because they were NaN or inf (expect 0).
  std::uint64_t nonFiniteSamples() const;
  RenderStats stats() const;
  std::uint32_t samples() const { return samples_; }
  // The frame's bands and each band's radiance sums on the device (vec4 accumulator pairs per
  // pixel: rgb, w = dropped samples), for passes that read the paths (render/correction/).
  const FrameLayout& layout() const { return layout_; }
  const gpu::Buffer& radiance(std::uint32_t band) const { return radiance_.at(band); }

private:
  const gpu::Context* context_;
  const scene::Scene* scene_;
  PathTraceSettings settings_;
  SceneBuffers sceneBuffers_;
  LightSet lights_;
  gpu::TexelBuffer lightBuffer_, emitterBuffer_; // RGBA32F texels (shaders/lib/light_bindings.glsl)
  gpu::Buffer treeBuffer_, scaleBuffer_;
  FrameLayout layout_;
  std::vector<gpu::Buffer> radiance_; // per band
  std::vector<gpu::Buffer> edges_;    // per band: which pixels an emitter's edge crosses (pathtrace.comp)
  StatusCounters status_;
  gpu::Kernel kernel_;
  gpu::CommandStream stream_;
  gpu::Timestamps timestamps_;
  std::uint32_t samples_ = 0;
  double wallSeconds_ = 0.0;
};

// Device memory the frame buffers need (beyond the scene).
std::uint64_t pathTraceBytesNeeded(std::uint32_t width, std::uint32_t height);

} // namespace obscura::render
