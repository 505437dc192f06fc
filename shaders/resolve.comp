#version 460
// resolve.comp — the Kahan sums of a frame band to the shared-exponent transport the fast relighting
// path reads (host_device.h, "resolve.comp and lightmix.comp"): T_s = (D_s + M_s + S_s) / n per
// light, then A_t = (A + A^spec) / n. Run once after the samples; every light edit reads them.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/accumulate.glsl"
#include "lib/rgb9e5.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { ResolvePush pc; };
// The Kahan sums through RGBA32F texel views (OBS_SUM_TEXEL): a quarter of the loads of an SSBO's.
layout(binding = kBindingResolveBasis) uniform samplerBuffer basis;
layout(binding = kBindingResolveEmissionBasis) uniform samplerBuffer emissionBasis;
layout(binding = kBindingResolveSpecularBasis) uniform samplerBuffer specularBasis;
layout(binding = kBindingResolveAmbient) uniform samplerBuffer ambient;
layout(binding = kBindingResolveSpecularAmbient) uniform samplerBuffer specularAmbient;
layout(std430, binding = kBindingResolveOutput) writeonly buffer Resolved { uint resolved[]; };
layout(std430, binding = kBindingResolveSampleCounts) readonly buffer SampleCounts { uint sampleCounts[]; };
layout(std430, binding = kBindingResolveDirty) readonly buffer Dirty { uint dirty[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint pixelCount = pc.width * pc.rows;
  if (pc.dirtyOnly != 0u) { // the dirty list's pixels only (a geometry edit's retrace)
    const uint base = dirtyListBase(pixelCount);
    if (pixel >= dirty[base + kQueueCount]) return;
    pixel = dirty[base + kQueueHeader + pixel];
  }
  if (pixel >= pixelCount) return;
  float inv = 1.0 / float(max(sampleCounts[pixel], 1u));
  const bool withSpecular = pc.specular != 0u;
  const uint stride = resolvedStride(pixelCount);
  for (uint s = pc.firstLight; s < pc.lightCount; ++s) {
    uint i = s * pixelCount + pixel;
    vec3 t = OBS_SUM_TEXEL(basis, i).rgb + OBS_SUM_TEXEL(emissionBasis, i).rgb;
    if (withSpecular) t += OBS_SUM_TEXEL(specularBasis, i).rgb;
    resolved[s * stride + pixel] = packRgb9e5(t * inv);
  }
  if (pc.ambient == 0u) return;
  vec3 a = OBS_SUM_TEXEL(ambient, pixel).rgb;
  if (withSpecular) a += OBS_SUM_TEXEL(specularAmbient, pixel).rgb;
  resolved[pc.lightSlots * stride + pixel] = packRgb9e5(a * inv);
}
