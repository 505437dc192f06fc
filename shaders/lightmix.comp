#version 460
// lightmix.comp — a light edit's frame in one pass from the resolved transport (resolve.comp):
//   display = tonemap( sum_s E_s T_s + I_a(E) A_t )      [SPEC §3, IVR eq. 4]
// reading 4 bytes per light and pixel, so that relighting stays interactive with many lights.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/srgb.glsl"
#include "lib/rgb9e5.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { LightMixPush pc; };
layout(std430, binding = kBindingLightMixResolved) readonly buffer Resolved { uint resolved[]; };
layout(std430, binding = kBindingLightMixEmissions) readonly buffer Emissions { vec4 emission[]; };
layout(std430, binding = kBindingLightMixOutput) writeonly buffer Out { uint display[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint pixelCount = pc.frame.x * pc.frame.y;
  if (pixel >= pixelCount) return;
  vec3 c = pc.ambient.rgb * unpackRgb9e5(resolved[pc.frame.w * pixelCount + pixel]);
  for (uint s = 0u; s < pc.frame.z; ++s) c += emission[s].rgb * unpackRgb9e5(resolved[s * pixelCount + pixel]);
  display[pixel] = displayRgba8(c, pc.ambient.w);
}
