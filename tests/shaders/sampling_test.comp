#version 460
// Runs the production sampling.glsl so tests/shaders/sampling_test.cpp can check its
// distributions (chi-square), the systematic cells, and agreement with the C++ twins.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { uvec4 params; }; // x = case count

// mode.x: what to run (the k* constants below); mode.y: n (systematic); mode.z: seed;
// mode.w: ray index (kModeWarps).
struct SamplingCase { uvec4 mode; vec4 a; vec4 b; vec4 c; };
const uint kModeCosine = 0u;     // 64 cosine samples from rng.glsl: xyz, w = 1
const uint kModeSystematic = 1u; // floor(64 / n) hits of n rays, one random offset per hit; w = 1
const uint kModeGrid = 2u;       // systematicGrid(n) in r[0].xy
const uint kModeTriangle = 3u;   // 64 points on triangle (a, b, c): xyz, w = area
const uint kModeWarps = 4u;      // deterministic warps of the inputs, see main()
const uint kModeSpherical = 5u;  // 64 directions uniform over the spherical triangle of unit a, b, c:
                                 // xyz, w = its solid angle; with mode.y = 1, a.w b.w c.w = u (one warp)
const uint kOutPerCase = 64u;

layout(std430, binding = 0) readonly buffer Cases { SamplingCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; }; // kOutPerCase per case

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.x) return;
  SamplingCase c = cases[i];
  uint base = i * kOutPerCase;
  for (uint k = 0u; k < kOutPerCase; ++k) results[base + k] = vec4(0.0);
  uint state = pcgHash(c.mode.z ^ pcgHash(i));
  if (c.mode.x == kModeCosine) {
    for (uint k = 0u; k < kOutPerCase; ++k) {
      vec2 u = vec2(rngNext(state), rngNext(state));
      results[base + k] = vec4(sampleCosineHemisphere(u), 1.0);
    }
  } else if (c.mode.x == kModeSystematic) {
    uint n = c.mode.y;
    uvec2 grid = systematicGrid(n);
    uint hits = kOutPerCase / n;
    for (uint h = 0u; h < hits; ++h) {
      vec2 offset = vec2(rngNext(state), rngNext(state)); // the hit's ONE random pair
      for (uint r = 0u; r < n; ++r) results[base + h * n + r] = vec4(sampleSystematic(r, grid, offset), 1.0);
    }
  } else if (c.mode.x == kModeGrid) {
    results[base] = vec4(vec2(systematicGrid(c.mode.y)), 0.0, 0.0);
  } else if (c.mode.x == kModeTriangle) {
    float area = triangleArea(c.a.xyz, c.b.xyz, c.c.xyz);
    for (uint k = 0u; k < kOutPerCase; ++k) {
      vec2 u = vec2(rngNext(state), rngNext(state));
      results[base + k] = vec4(sampleUniformTriangle(u, c.a.xyz, c.b.xyz, c.c.xyz), area);
    }
  } else if (c.mode.x == kModeSpherical) {
    float area = sphericalTriangleArea(c.a.xyz, c.b.xyz, c.c.xyz);
    if (c.mode.y == 1u) {
      results[base] = vec4(sampleSphericalTriangle(vec2(c.a.w, c.b.w), c.a.xyz, c.b.xyz, c.c.xyz), area);
      return;
    }
    for (uint k = 0u; k < kOutPerCase; ++k) {
      vec2 u = vec2(rngNext(state), rngNext(state));
      results[base + k] = vec4(sampleSphericalTriangle(u, c.a.xyz, c.b.xyz, c.c.xyz), area);
    }
  } else if (c.mode.x == kModeWarps) {
    // a.xy = u, a.zw = systematic offset, b.xyz = normal, c.xyz = local direction.
    vec3 w = sampleCosineHemisphere(c.a.xy);
    results[base + 0u] = vec4(w, cosineHemispherePdf(w.z));
    results[base + 1u] = vec4(invertCosineHemisphereSample(w), 0.0, 0.0);
    results[base + 2u] = vec4(sampleSystematic(c.mode.w, systematicGrid(c.mode.y), c.a.zw), 0.0);
    vec3 t, b;
    orthonormalBasis(c.b.xyz, t, b);
    results[base + 3u] = vec4(t, 0.0);
    results[base + 4u] = vec4(b, 0.0);
    results[base + 5u] = vec4(toWorld(c.c.xyz, t, b, c.b.xyz), 0.0);
  }
}
