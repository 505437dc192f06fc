#version 460
// lightmix.comp — a light edit's frame in one pass from the resolved transport (resolve.comp):
//   display = tonemap( sum_s E_s T_s + I_a(E) A_t )      [SPEC §3, IVR eq. 4]
// reading 4 bytes per light and pixel, so that relighting stays interactive with many lights.
// Four neighbouring pixels per invocation, read as one RGBA32UI texel per light: on lavapipe a
// load with per-lane addresses costs a scalar load per lane, so one 16-byte texel per lane is a
// quarter of the loads of four words (measured: docs/BENCHMARKS.md).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/srgb.glsl"
#include "lib/rgb9e5.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { LightMixPush pc; };
layout(binding = kBindingLightMixResolved) uniform usamplerBuffer resolved;
layout(std430, binding = kBindingLightMixEmissions) readonly buffer Emissions { vec4 emission[]; };
layout(std430, binding = kBindingLightMixOutput) writeonly buffer Out { uint display[]; };

void main() {
  const uint quad = gl_GlobalInvocationID.x;
  const uint pixelCount = pc.width * pc.rows;
  const uint first = quad * kResolvedPixelAlign;
  if (first >= pixelCount) return;
  const uint rowTexels = resolvedStride(pixelCount) / kResolvedPixelAlign; // texels per light
  uvec4 a = texelFetch(resolved, int(pc.lightSlots * rowTexels + quad));
  vec3 c0 = pc.ambient * unpackRgb9e5(a.x), c1 = pc.ambient * unpackRgb9e5(a.y);
  vec3 c2 = pc.ambient * unpackRgb9e5(a.z), c3 = pc.ambient * unpackRgb9e5(a.w);
  for (uint s = 0u; s < pc.lightCount; ++s) {
    const uvec4 t = texelFetch(resolved, int(s * rowTexels + quad));
    const vec3 e = emission[s].rgb;
    c0 += e * unpackRgb9e5(t.x);
    c1 += e * unpackRgb9e5(t.y);
    c2 += e * unpackRgb9e5(t.z);
    c3 += e * unpackRgb9e5(t.w);
  }
  display[first] = displayRgba8(c0, pc.exposureScale);
  if (first + 1u < pixelCount) display[first + 1u] = displayRgba8(c1, pc.exposureScale);
  if (first + 2u < pixelCount) display[first + 2u] = displayRgba8(c2, pc.exposureScale);
  if (first + 3u < pixelCount) display[first + 3u] = displayRgba8(c3, pc.exposureScale);
}
