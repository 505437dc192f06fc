#version 460
// denoise_edges.comp — the denoiser's last pass: pixels an edge crosses, resolved from camera rays
// of their own [ours].
//
// The filter smooths each surface's light but cannot fix how much of a pixel each surface covers:
// a 1-spp frame's pixel that a silhouette, a crease or an emitter's border crosses shows one
// surface whole. Those pixels then hold most of a denoised frame's error (the Cornell box at
// 128x128: 75 % of it off the lamp, in 1 % of the pixels; docs/BENCHMARKS.md), and only more
// points in them make it fall. Here each such pixel traces K camera rays through points of its
// own (cheap: a closest hit, no shading). Each ray's surface is looked up among the 3x3 pixels
// around it (same material, normal and plane as their guide: the filter's own test) and takes
// that pixel's filtered light; what the ray sees emit is taken from the ray itself (its emitter's
// unit emission times the E_s compose used), the sky's too. The mean over the rays is blended
// with the pixel's own estimate by their counts, (n C + sum R_k) / (n + K): the pixel's box filter
// with K more points of coverage, the pass fading as samples accumulate.
//
// Geometric edges are resolved only in frames of one sample (and no history): with more, the
// pixel's own points measure its coverage, and the light taken from a neighbour a pixel away is
// the larger error (measured: docs/BENCHMARKS.md). An emitter's border is resolved at any count:
// there the rays' own emission, exact per ray, is nearly all of the pixel (a lamp ~100x its
// surroundings), and what they take from the neighbours is a rounding error beside it.
//
// Which pixels: those whose guide differs from a neighbour's (another surface, found the way the
// filter stops at it) or whose seen emission does (an emitter's border, where the radiance jumps
// by a hundred times: more rays, `emitterRays`). A pixel with no such neighbour is copied.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/surface.glsl"
#include "lib/material.glsl"
#include "lib/rng.glsl"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(push_constant) uniform Push { DenoiseEdgesPush pc; };
layout(std430, set = 0, binding = kBindingEdgesParams) readonly buffer Params { DenoiseParams params; };
layout(std430, set = 0, binding = kBindingEdgesGuide) readonly buffer GuideIn { uvec4 guide[]; };
layout(std430, set = 0, binding = kBindingEdgesRemodulated) readonly buffer Remodulated { vec4 remodulated[]; };
layout(std430, set = 0, binding = kBindingEdgesEmission) readonly buffer Emission { vec4 emission[]; };
layout(std430, set = 0, binding = kBindingEdgesLightScales) readonly buffer LightScales { vec4 lightScales[]; };
layout(std430, set = 0, binding = kBindingEdgesEmissions) readonly buffer Emissions { vec4 emissions[]; };
layout(std430, set = 0, binding = kBindingEdgesOut) writeonly buffer Out { vec4 combined[]; };

// A surface lies on a neighbour's plane when it is within this many pixel widths (at the
// neighbour's depth) of it: a crease or a step is many widths off, a slanted plane none.
const float kPlanePixels = 2.0;

float planeTolerance(Guide g, uvec2 size) { return kPlanePixels * pixelFootprint(params.camera, g.depth, size); }

// Whether the seen emissions of two pixels differ (beyond the halves they are summed in).
bool emissionDiffers(vec3 a, vec3 b) { return any(greaterThan(abs(a - b), 1e-3 * max(a, b) + 1e-6)); }

void main() {
  const uvec2 size = params.frame.xy;
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= size.x || p.y >= size.y) return;
  const uint pixel = p.y * size.x + p.x;
  const vec4 own = remodulated[pixel];
  const float n = max(own.w, 1.0); // the samples (and history) the pixel's own estimate counts for
  if (pc.geometryRays == 0u) {
    combined[pixel] = vec4(own.rgb, 1.0);
    return;
  }
  const Guide g = decodeGuide(guide[pixel]);
  const vec3 ownPoint = pixelPoint(params.camera, ivec2(p), size, g.depth);
  const vec3 ownEmission = emission[pixel].rgb;

  // The 3x3 neighbourhood: does another surface, or another emission, show in it?
  bool geometryEdge = false, emitterEdge = false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const ivec2 q = ivec2(p) + ivec2(dx, dy);
      if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(size)))) continue;
      const uint qi = uint(q.y) * size.x + uint(q.x);
      const Guide gq = decodeGuide(guide[qi]);
      const bool same = guideHit(g) ? sameSurface(g, ownPoint, gq, pixelPoint(params.camera, q, size, gq.depth),
                                                  planeTolerance(g, size))
                                    : !guideHit(gq);
      geometryEdge = geometryEdge || !same;
      emitterEdge = emitterEdge || emissionDiffers(ownEmission, emission[qi].rgb);
    }
  // A geometric edge only in a frame of one sample (see above); an emitter's border always.
  if (!emitterEdge && !(geometryEdge && n <= 1.0)) {
    combined[pixel] = vec4(own.rgb, 1.0);
    return;
  }

  const uint rays = emitterEdge ? max(pc.emitterRays, pc.geometryRays) : pc.geometryRays;
  const uint skySlot = floatBitsToUint(params.camera.up.w);
  uint rng = rngSeed(p, 0x6564u, 0u); // a fixed pattern per pixel: the same image every call
  const vec2 shift = vec2(rngNext(rng), rngNext(rng));
  StepBudget budget = newStepBudget();
  vec3 sum = vec3(0.0);
  for (uint j = 0u; j < rays; ++j) {
    const vec3 direction = cameraRayDirection(params.camera, vec2(p) + pixelSampleOffset(j, shift), vec2(size));
    const RayHit hit = traceWithBudget(budget, params.camera.origin.xyz, direction, 0.0, 1.0 / 0.0, false);
    if (hit.primitive == kTruncatedHit) {
      sum += own.rgb; // out of loop budget (counted in the status word): the pixel's own estimate
      continue;
    }
    if (!rayHitValid(hit) || hit.primitive == kInvalidIndex) {
      if (skySlot < pc.lightCount) sum += emissions[skySlot].rgb; // the sky at unit radiance times its E_s
      continue;
    }
    const Surface s = surfaceAt(hit, params.camera.origin.xyz, direction);
    // The neighbour on the ray's surface whose plane it lies nearest (none: the pixel's own light).
    const uint material = min(s.material, kDenoiseNoMaterial - 1u);
    uint best = kInvalidIndex;
    float bestDistance = 1.0;
    for (int c = 0; c < 9; ++c) {
      const ivec2 q = ivec2(p) + ivec2(c % 3 - 1, c / 3 - 1);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(size)))) continue;
      const uint qi = uint(q.y) * size.x + uint(q.x);
      const Guide gq = decodeGuide(guide[qi]);
      if (!guideHit(gq) || gq.material != material || dot(gq.normal, s.shadingNormal) <= kSameSurfaceCos) continue;
      const float d = planeDistance(pixelPoint(params.camera, q, size, gq.depth), gq.normal, s.position,
                                    planeTolerance(gq, size));
      if (d < bestDistance) {
        bestDistance = d;
        best = qi;
      }
    }
    sum += best != kInvalidIndex ? remodulated[best].rgb - emission[best].rgb : own.rgb - ownEmission;
    if (s.lightGroup != kInvalidIndex) {
      const vec3 e = materialEmission(materialAt(s.material), s.uv, s.frontFacing);
      sum += unitEmission(e, lightScales[s.lightGroup].rgb) * emissions[s.lightGroup].rgb;
    }
  }
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
  combined[pixel] = vec4((n * own.rgb + sum) / (n + float(rays)), 1.0);
}
