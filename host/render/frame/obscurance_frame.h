// obscurance_frame.h — frame-lifetime state of the obscurance renderer: everything that depends on
// the resolution and the number of lights, split into bands (frame_layout.h).
//
// Per band: the G-buffer of the current sample, the primary AOV accumulators, and the basis
// buffers that make the image linear in every light's emission [SPEC §3]:
//   basis          D_s  direct light of light s at unit emission      [light][pixel] Kahan pairs
//   emissionBasis  M_s  emission of light s the camera sees, unit E_s  [light][pixel]
//   ambient        A    albedo x W_c (rgb), W (w)                      [pixel]
//   specularBasis / specularAmbient: the same gathered along specular paths (glossy scenes only)
// plus the specular queue, the composed AOVs and the tonemapped display bytes. The frame's ray
// and truncation counters live here too.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/command_stream.h"
#include "gpu/context.h"
#include "render/frame/frame_layout.h"
#include "render/frame/frame_progress.h"
#include "render/status_counters.h"
#include "shared/host_device.h"

namespace obscura::render {

// One frame-lifetime buffer kind and its bytes per pixel (per light where perLight).
struct FrameBufferKind {
  std::string name;
  std::uint64_t bytesPerPixel = 0;
  bool perLight = false;
  // Whether the kind's size decides the bands. The kept rays do not: they are kept for as many
  // samples as fit in a band's buffer (ObscuranceFrame's constructor lowers keptRaySamples).
  bool splitsBands = true;
};

// What a frame holds besides the basis buffers: only what was asked for is allocated.
struct FrameContents {
  bool specular = false;             // glossy scene: specular basis, ambient and queue
  bool primaryAovs = true;           // albedo, normal, depth, ... (primary.comp's accumulators)
  std::uint32_t composedSlots = 6;   // gpu::kComposeSlots, or 1 when only `combined` is wanted
  // Lights that may be added: the per-light buffers have this many spare slots from the start,
  // so adding a light clears one slot instead of re-allocating and copying every basis buffer.
  std::uint32_t spareLightSlots = 0;
  // Samples whose rays are kept (shaders/lib/kept_rays.glsl): the specular paths' lobe hits
  // (gpu::kPathHitsPerSample per pixel and sample) and the primary hits' shadow rays
  // (keptShadowRays per pixel and sample), so that an added light's gather and a geometry edit's
  // probes follow them without tracing or drawing them again (the lobe hits only with `specular`).
  std::uint32_t keptRaySamples = 0;
  std::uint32_t keptShadowRays = 0; // N_s, at most gpu::kMaxKeptShadowRays
};


class ObscuranceFrame {
public:
  struct Band {
    FrameBand rows;
    // The G-buffer: written by primary.comp as an SSBO, read by the shading passes through an
    // RGBA32F texel view (kTexelsPerGBuffer texels a pixel, lib/shading_bindings.glsl).
    gpu::TexelBuffer gbuffer;
    gpu::Buffer aovs, queue, specularPaths, composed, display;
    // The light and ambient Kahan sums (vec4 pairs, lib/accumulate.glsl) with RGBA32F views: the
    // shading passes add to them as storage texel buffers, compose.comp and resolve.comp read them
    // as uniform ones (primary.comp and clear.comp bind them as SSBOs). lavapipe moves a texel as
    // one 16-byte vector per lane, an SSBO vec4 as four scalar accesses (docs/BENCHMARKS.md).
    gpu::TexelBuffer basis, emissionBasis, ambient, specularBasis, specularAmbient;
    gpu::TexelBuffer resolved; // RGB9E5 T_s per light, then A_t (resolve.comp), for light edits:
                               // lightmix.comp reads four pixels at a time as RGBA32UI texels
    gpu::Buffer hitBounds; // per pixel, the box of its primary hits over samples (geometry edits)
    gpu::Buffer dirty;     // per pixel, 1 = retrace after a geometry edit, then the list of those
                           // pixels with its indirect dispatch (dirty.comp; host_device.h), then
                           // the changed boxes for the probing passes (dirtyBoxesBase)
    gpu::Buffer sampleCounts; // per pixel, the samples its sums hold (primary.comp); compose divides by it
    gpu::Buffer emitterEdges; // per pixel, 1 = an emitter's edge crosses it (primary.comp's probe at its first sample)
    gpu::Buffer pathHits;     // per kept sample and pixel, its specular path's lobe hits (lib/kept_rays.glsl)
    gpu::Buffer shadowRays;   // per kept sample and pixel, the shadow rays at its primary hit and path vertices
  };

  // `maxBufferBytes` 0 = the device's per-buffer limit, `maxTexelElements` 0 = its per-texel-view
  // limit (smaller ones test banding).
  ObscuranceFrame(const gpu::Context& context, std::uint32_t width, std::uint32_t height, std::uint32_t lights,
                  const FrameContents& contents, std::uint64_t maxBufferBytes = 0,
                  std::uint64_t maxTexelElements = 0, RowRange rows = {});

  // The buffer kinds a frame allocates, from which both the allocation and the memory figures
  // are computed.
  static std::vector<FrameBufferKind> bufferKinds(const FrameContents& contents);
  // Device bytes a frame of this shape allocates (all bands, all buffers).
  static std::uint64_t bytesNeeded(std::uint32_t width, std::uint32_t height, std::uint32_t lights,
                                   const FrameContents& contents);

  const FrameLayout& layout() const { return layout_; }
  Band& band(std::size_t i) { return bands_[i]; }
  const Band& band(std::size_t i) const { return bands_[i]; }
  std::uint32_t lightCount() const { return lights_; }
  bool specular() const { return contents_.specular; }
  // Bytes per pixel of one kept sample's lobe hits.
  static constexpr std::uint64_t kPathHitBytesPerSample = gpu::kPathHitsPerSample * 16;
  // Bytes per pixel of one kept sample's shadow rays (at the primary hit and the path's vertices),
  // and of all its kept rays.
  static std::uint64_t keptShadowRayBytesPerSample(std::uint32_t shadowRays) {
    return 16ull * shadowRays * (gpu::kPathHitsPerSample + 1);
  }
  static std::uint64_t keptRayBytesPerSample(std::uint32_t shadowRays, bool specular) {
    return (specular ? kPathHitBytesPerSample : 0) + keptShadowRayBytesPerSample(shadowRays);
  }
  const FrameContents& contents() const { return contents_; }

  const gpu::Buffer& status() const { return status_.buffer(); }
  std::vector<std::uint32_t> statusWords() const { return status_.words(); }
  void resetStatus() { status_.reset(); }

  // Where band `band`'s dirty list (its indirect dispatch arguments) starts in its dirty buffer.
  vk::DeviceSize dirtyListOffset(std::size_t band) const {
    return vk::DeviceSize(gpu::dirtyListBase(static_cast<std::uint32_t>(layout_.bandPixels(band)))) * 4;
  }

  // Device bytes allocated now (the real buffers' sizes).
  std::uint64_t bytes() const;

  // Inserts a light slot (zero transport) at `index`; the slots from there move up one.
  // InputError when the spare slots are used up.
  void addLightSlot(gpu::CommandStream& stream, std::uint32_t index);
  // Drops light slot `index`; the slots after it move down one (lights keep their order).
  void removeLightSlot(gpu::CommandStream& stream, std::uint32_t index);
  std::uint32_t lightCapacity() const { return maxLights_; }

  // How far the sums have come (samples, the G-buffer's sample, what is resolved).
  FrameProgress& progress() { return progress_; }
  const FrameProgress& progress() const { return progress_; }

  const gpu::Context* context_;
  FrameLayout layout_;
  std::uint32_t lights_ = 0;
  std::uint32_t maxLights_ = 0;
  FrameContents contents_;
  std::vector<Band> bands_;
  StatusCounters status_;
  FrameProgress progress_;
};

} // namespace obscura::render
