// shading_bindings.glsl — bindings 6..14 shared by the shading passes (shadow, obscurance,
// specular): the G-buffer, the lights and the accumulation buffers [SPEC §3].
#ifndef OBSCURA_SHADING_BINDINGS_GLSL
#define OBSCURA_SHADING_BINDINGS_GLSL

#include "band.glsl"

layout(std430, set = 0, binding = kBindingGBuffer) readonly buffer GBuffer { GBufferTexel gbuffer[]; };
layout(std430, set = 0, binding = kBindingLights) readonly buffer LightBuffer { GpuLight lights[]; };
layout(std430, set = 0, binding = kBindingEmitters) readonly buffer EmitterBuffer { GpuEmitter emitters[]; };
// basis[light * pixelCount + pixel] += D_s contributions (unit emission), summed over samples.
layout(std430, set = 0, binding = kBindingBasis) buffer BasisBuffer { vec4 basis[]; };
// ambient[pixel].rgb += R(P) W_c (or R(P) W), .w += W, summed over samples.
layout(std430, set = 0, binding = kBindingAmbient) buffer AmbientBuffer { vec4 ambient[]; };

// The same two along specular paths (specular.comp), kept apart for the "specular" AOV.
layout(std430, set = 0, binding = kBindingSpecularBasis) buffer SpecularBasisBuffer { vec4 specularBasis[]; };
layout(std430, set = 0, binding = kBindingSpecularAmbient) buffer SpecularAmbientBuffer { vec4 specularAmbient[]; };
// queue[0..3] = indirect dispatch groups (x, y, z) and the entry count; pixel indices follow.
layout(std430, set = 0, binding = kBindingSpecularQueue) buffer SpecularQueue { uint queue[]; };
layout(std430, set = 0, binding = kBindingLightScales) readonly buffer LightScales { vec4 lightScales[]; };
layout(std430, set = 0, binding = kBindingDirty) readonly buffer DirtyMask { uint dirty[]; };
// Per pixel, the box of its hits and specular path vertices (primary.comp starts it; specular.comp
// grows it), for the dirty pixels of a geometry edit.
layout(std430, set = 0, binding = kBindingHitBounds) buffer HitBounds { vec4 hitBounds[]; };

layout(push_constant) uniform Push { ShadePush pc; };

// Whether this pass skips `pixel`: a retrace after a geometry edit runs the dirty pixels only.
bool skipClean(uint pixel) { return (pc.band.z & kShadeFlagDirtyOnly) != 0u && dirty[pixel] == 0u; }

// The pixel of this invocation: over the band in 2D, or (a retrace, kShadeFlagDirtyOnly) over the
// band's dirty list, dispatched indirectly.
BandPixel shadedPixel() {
  if ((pc.band.z & kShadeFlagDirtyOnly) == 0u) return bandPixel(gl_GlobalInvocationID.xy, pc.frame.xy, pc.band.xy);
  const uint base = dirtyListBase(pc.frame.x * pc.band.y), entry = listEntry(), count = dirty[base + kQueueCount];
  return listedPixel(entry, count, entry < count ? dirty[base + kQueueHeader + entry] : 0u, pc.frame.xy, pc.band.xy);
}

#endif
