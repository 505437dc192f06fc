// shading_bindings.glsl — bindings 6..17 shared by the shading passes (shadow, obscurance,
// specular): the G-buffer, the lights and the accumulation buffers [SPEC §3].
#ifndef OBSCURA_SHADING_BINDINGS_GLSL
#define OBSCURA_SHADING_BINDINGS_GLSL

#include "band.glsl"
#include "probe.glsl"
#include "shaft.glsl"
#include "light_bindings.glsl"

// The G-buffer of the current sample (primary.comp writes it as an SSBO), read through a texel view:
// one vector gather per texel, where an SSBO read is a scalar load per lane per word on lavapipe.
layout(set = 0, binding = kBindingGBuffer) uniform samplerBuffer gbufferTexels;
GBufferTexel gbufferAt(uint pixel) {
  const int at = int(pixel * kTexelsPerGBuffer);
  return GBufferTexel(texelFetch(gbufferTexels, at), texelFetch(gbufferTexels, at + 1),
                      texelFetch(gbufferTexels, at + 2), texelFetch(gbufferTexels, at + 3));
}
layout(std430, set = 0, binding = kBindingLightTree) readonly buffer LightTreeBuffer { GpuLightNode lightTree[]; };
// The Kahan sums (vec4 pairs, OBS_ACCUMULATE_TEXEL), as RGBA32F storage texel buffers: a texel is one
// vector access a lane on lavapipe, an SSBO vec4 four scalar ones.
// basis[light * pixelCount + pixel] += D_s contributions (unit emission), summed over samples.
layout(set = 0, binding = kBindingBasis, rgba32f) uniform imageBuffer basis;
// ambient[pixel].rgb += R(P) W_c (or R(P) W), .w += W, summed over samples.
layout(set = 0, binding = kBindingAmbient, rgba32f) uniform imageBuffer ambient;

// The same two along specular paths (specular.comp), kept apart for the "specular" AOV.
layout(set = 0, binding = kBindingSpecularBasis, rgba32f) uniform imageBuffer specularBasis;
layout(set = 0, binding = kBindingSpecularAmbient, rgba32f) uniform imageBuffer specularAmbient;
// queue[0..3] = indirect dispatch groups (x, y, z) and the entry count; pixel indices follow.
// Two such queues take turns, one per path depth (specularQueueBase).
layout(std430, set = 0, binding = kBindingSpecularQueue) buffer SpecularQueue { uint queue[]; };
// The specular paths' state between vertices, kSpecularPathTexels per pixel (specular.comp).
layout(std430, set = 0, binding = kBindingSpecularPaths) buffer SpecularPaths { vec4 specularPaths[]; };
layout(std430, set = 0, binding = kBindingLightScales) readonly buffer LightScales { vec4 lightScales[]; };
layout(std430, set = 0, binding = kBindingDirty) buffer DirtyMask { uint dirty[]; }; // probes mark it
// Per pixel, the box of its hits and specular path vertices (primary.comp starts it; specular.comp
// grows it), for the dirty pixels of a geometry edit.
layout(std430, set = 0, binding = kBindingHitBounds) buffer HitBounds { vec4 hitBounds[]; };
// The specular paths' lobe hits of the samples the frame keeps (kShadeFlagKeptRays, lib/kept_rays.glsl).
layout(std430, set = 0, binding = kBindingPathHits) buffer PathHits { uvec4 pathHits[]; };
// The primary hits' shadow rays of the samples the frame keeps (kShadeFlagKeptRays, lib/kept_rays.glsl).
layout(std430, set = 0, binding = kBindingKeptShadowRays) buffer KeptShadowRays { vec4 keptShadowRays[]; };

layout(push_constant) uniform Push { ShadePush pc; };

// The variant of a kernel for one light alone (kSpecConstantPerLight). The probing variant reads
// the flag, so that a probe of a per-light dispatch follows the same code; the plain kernel leaves
// the per-light code out (on lavapipe, code no invocation takes still costs: registers are
// allocated over the whole shader).
layout(constant_id = kSpecConstantPerLight) const bool kPerLight = false;

// Whether this dispatch shades light pc.light alone (kShadeFlagPerLight): the per-light variant,
// or a probe of a per-light dispatch. The host sends every other per-light dispatch to that variant.
bool shadesOneLight() { return kPerLight || (kProbe && (pc.dispatchFlags & kShadeFlagPerLight) != 0u); }

// Whether this pass skips `pixel`: a retrace after a geometry edit runs the dirty pixels only, and
// a probing pass the candidates that no probe has found dirty yet (mask 1, dirty.comp).
bool skipClean(uint pixel) {
  if ((pc.dispatchFlags & kShadeFlagProbe) != 0u) return dirty[pixel] != 1u;
  return (pc.dispatchFlags & kShadeFlagDirtyOnly) != 0u && dirty[pixel] == 0u;
}

// The pixel of this invocation: over the band in 2D, or (a retrace, kShadeFlagDirtyOnly) over the
// band's dirty list, dispatched indirectly.
BandPixel shadedPixel() {
  if ((pc.dispatchFlags & kShadeFlagDirtyOnly) == 0u) return bandPixel(gl_GlobalInvocationID.xy, uvec2(pc.width, pc.height), uvec2(pc.firstRow, pc.rows));
  const uint base = dirtyListBase(pc.width * pc.rows), entry = listEntry(), count = dirty[base + kQueueCount];
  return listedPixel(entry, count, entry < count ? dirty[base + kQueueHeader + entry] : 0u, uvec2(pc.width, pc.height), uvec2(pc.firstRow, pc.rows));
}

// Starts a probing kernel (kProbe, dispatched with kShadeFlagProbe) if this is one: the changed
// boxes from the dirty buffer's tail (DirtyPass::record). Returns whether it is.
bool beginProbe() {
  if (!kProbe) return false;
  const uint base = dirtyBoxesBase(pc.width * pc.rows);
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    uint at = base + 8u * b;
    gProbeUsed[b] = uintBitsToFloat(dirty[at + 3u]) != 0.0;
    gProbeLo[b] = uintBitsToFloat(uvec3(dirty[at], dirty[at + 1u], dirty[at + 2u]));
    gProbeHi[b] = uintBitsToFloat(uvec3(dirty[at + 4u], dirty[at + 5u], dirty[at + 6u]));
  }
  return true;
}

// Whether a shadow ray from p to any of the first `lightCount` lights may meet a changed box: the
// shafts from p to the lights' bounds (lib/shaft.glsl, as dirty.comp tests a hit box). Where none
// does, a probe need not draw p's light samples: none of its shadow rays can meet a box.
bool probeShadowRaysMayMeet(vec3 p, uint lightCount) {
  const uint lightsAt = dirtyLightsBase(pc.width * pc.rows);
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (!gProbeUsed[b]) continue;
    vec3 bc = 0.5 * (gProbeLo[b] + gProbeHi[b]), bh = 0.5 * (gProbeHi[b] - gProbeLo[b]);
    for (uint s = 0u; s < lightCount; ++s) {
      uint at = lightsAt + 8u * s;
      vec4 light = uintBitsToFloat(uvec4(dirty[at], dirty[at + 1u], dirty[at + 2u], dirty[at + 3u]));
      vec3 extent = uintBitsToFloat(uvec3(dirty[at + 4u], dirty[at + 5u], dirty[at + 6u]));
      bool meets = light.w != 0.0 ? meetsInfiniteShaft(bc, bh, p, vec3(0.0), extent)
                                  : meetsShaft(bc, bh, p, vec3(0.0), light.xyz, extent);
      if (meets) return true;
    }
  }
  return false;
}

// Ends a probed pixel: marked dirty for certain when one of its rays met a changed box.
void endProbe(uint pixel) {
  if (kProbe && gProbeMet) dirty[pixel] = kDirtyCertain;
}

#endif
