#version 460
// Runs the production ray/box slab test on (ray, box) pairs.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/intersect.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { uvec4 params; };
struct BoxCase { GpuRay ray; vec4 lo; vec4 hi; };
layout(std430, binding = 0) readonly buffer Cases { BoxCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; }; // hit, tnear, tfar, 0

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.x) return;
  BoxCase c = cases[i];
  vec2 s = intersectBox(c.lo.xyz, c.hi.xyz, c.ray.origin.xyz, safeReciprocal(c.ray.direction.xyz),
                        c.ray.origin.w, c.ray.direction.w);
  results[i] = vec4(s.x <= s.y ? 1.0 : 0.0, s.x, s.y, 0.0);
}
