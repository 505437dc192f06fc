#version 460
// Runs the production intersect.glsl on (ray, triangle) pairs so the host can compare each result
// with the CPU twin (host/bvh/triangle_intersect.cpp).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/intersect.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { uvec4 params; }; // x = case count
struct IntersectCase { GpuRay ray; vec4 v0; vec4 v1; vec4 v2; };
layout(std430, binding = 0) readonly buffer Cases { IntersectCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; }; // hit, t, u, v

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.x) return;
  IntersectCase c = cases[i];
  WatertightRay r = prepareWatertightRay(c.ray.origin.xyz, c.ray.direction.xyz);
  float t, u, v;
  bool hit = intersectTriangle(r, c.v0.xyz, c.v1.xyz, c.v2.xyz, c.ray.origin.w, c.ray.direction.w, t, u, v);
  results[i] = vec4(hit ? 1.0 : 0.0, t, u, v);
}
