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
// unit emission times the E_s compose used), the sky's too. The rays' means are blended with the
// pixel's own estimate by the points behind each: its shading (C - M) has the frame's n samples,
// its seen emission M the renderer's emission rays at each (--emission-samples), so
//   (n (C - M) + sum S_k) / (n + K)  +  (n E M + sum M_k) / (n E + K):
// the pixel's box filter with K more points of coverage, fading as samples accumulate.
//
// A geometric edge's shading is resolved only in a frame of one sample (and no history): with
// more, the pixel's own points measure its coverage, and the light taken from a neighbour a pixel
// away is the larger error (measured: docs/BENCHMARKS.md). An emitter's border is resolved at any
// count, its emission only: there the seen emission, exact per ray, is nearly all of the pixel (a
// lamp ~100x its surroundings), and more points of it are what the pixel needs.
//
// Which pixels: those whose guide differs from a neighbour's (another surface, found the way the
// filter stops at it) or whose seen emission does (an emitter's border: rays by its step, up to
// `emitterRays`, see main). A pixel with no such neighbour is copied.
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

// Emitter-border rays per unit of an emission step over I_a's luminance (see main).
const float kEdgeRaysPerContrast = 8.0;

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
  // The 3x3 pixels as the rays will compare with them, read once: each one's guide, point (at its
  // mean depth), plane tolerance, and filtered light without the emission. `inside`: in the image.
  Guide guides[9];
  vec3 points[9];
  float tolerance[9];
  vec3 light[9];
  vec3 seen[9];
  bool inside[9];
  for (int c = 0; c < 9; ++c) {
    const ivec2 q = ivec2(p) + ivec2(c % 3 - 1, c / 3 - 1);
    inside[c] = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, ivec2(size)));
    const uint qi = inside[c] ? uint(q.y) * size.x + uint(q.x) : pixel;
    guides[c] = decodeGuide(guide[qi]);
    points[c] = pixelPoint(params.camera, q, size, guides[c].depth);
    tolerance[c] = planeTolerance(guides[c], size);
    seen[c] = emission[qi].rgb;
    light[c] = remodulated[qi].rgb - seen[c];
  }

  // Does another surface (the filter's own test, sameSurface), or another emission, show in the 3x3?
  bool geometryEdge = false, emitterEdge = false;
  const vec3 ownEmission = seen[4];
  float emissionStep = 0.0; // the largest jump in seen emission (luminance)
  for (int c = 0; c < 9; ++c) {
    if (c == 4 || !inside[c]) continue;
    emissionStep = max(emissionStep, abs(luminance(seen[c]) - luminance(ownEmission)));
    const bool same = guideHit(guides[4]) ? sameSurface(guides[4], points[4], guides[c], points[c], tolerance[4])
                                          : !guideHit(guides[c]);
    geometryEdge = geometryEdge || !same;
    emitterEdge = emitterEdge || emissionDiffers(ownEmission, seen[c]);
  }
  // A geometric edge only in a frame of one sample (see above); an emitter's border always (its
  // emission alone beyond one sample).
  if (!emitterEdge && !(geometryEdge && n <= 1.0)) {
    combined[pixel] = vec4(own.rgb, 1.0);
    return;
  }

  // At an emitter's border, rays by the emission's step against the scene's radiance scale (I_a):
  // K well-spread points leave a coverage error of about step / K, held to an eighth of I_a. RMSE
  // is a frame's measure, so the scale is the frame's, not the light around the pixel (which
  // gave modern-hall's lamps 8 rays and a 1-spp frame's RMSE 0.101 against 0.088 with 64).
  // Measured: the Cornell box lamp takes 256 (the most), modern-hall's lamps 8-57 (median 43).
  const float contrast = emissionStep / max(pc.ambientLuminance, 1e-3);
  const uint emitterRays = uint(clamp(ceil(kEdgeRaysPerContrast * contrast), float(pc.geometryRays), float(pc.emitterRays)));
  const uint rays = emitterEdge ? max(emitterRays, pc.geometryRays) : pc.geometryRays;
  const uint skySlot = floatBitsToUint(params.camera.up.w);
  uint rng = rngSeed(p, 0x6564u, 0u); // a fixed pattern per pixel: the same image every call
  const vec2 shift = vec2(rngNext(rng), rngNext(rng));
  StepBudget budget = newStepBudget();
  const bool resolveShading = n <= 1.0; // beyond one sample the rays bring the emission alone
  vec3 shading = vec3(0.0), emitted = vec3(0.0); // the rays' sums
  uint traced = 0u, mostPasses = 0u;
  for (uint j = 0u; j < rays; ++j) {
    // Up to K rays while the loop budget lasts (the limiter, LAVAPIPE.md): the next ray may take
    // twice the passes the most costly one so far took; the rays not traced are left to the
    // pixel's own estimate (K counts the traced ones), and no traversal is cut short.
    if (subgroupPasses[gl_SubgroupID] + 2u * mostPasses + 64u > kMaxTraversalSteps) break;
    const vec3 direction = cameraRayDirection(params.camera, vec2(p) + pixelSampleOffset(j, shift), vec2(size));
    const RayHit hit = traceWithBudget(budget, params.camera.origin.xyz, direction, 0.0, 1.0 / 0.0, false);
    mostPasses = max(mostPasses, subgroupMax(hit.steps));
    ++traced;
    if (hit.primitive == kTruncatedHit) {
      shading += light[4]; // out of loop budget (counted in the status word): the pixel's own
      emitted += ownEmission;
      continue;
    }
    if (!rayHitValid(hit) || hit.primitive == kInvalidIndex) {
      if (skySlot < pc.lightCount) emitted += emissions[skySlot].rgb; // the sky at unit radiance times its E_s
      continue;
    }
    const Surface s = surfaceAt(hit, params.camera.origin.xyz, direction);
    if (resolveShading) {
      // The neighbour on the ray's surface whose plane it lies nearest (none: the pixel's own light).
      const uint material = min(s.material, kDenoiseNoMaterial - 1u);
      vec3 taken = light[4];
      float bestDistance = 1.0;
      for (int c = 0; c < 9; ++c) {
        const Guide gq = guides[c];
        if (!inside[c] || !guideHit(gq) || gq.material != material || dot(gq.normal, s.shadingNormal) <= kSameSurfaceCos)
          continue;
        const float d = planeDistance(points[c], gq.normal, s.position, tolerance[c]);
        if (d < bestDistance) {
          bestDistance = d;
          taken = light[c];
        }
      }
      shading += taken;
    }
    if (s.lightGroup != kInvalidIndex) {
      const vec3 e = materialEmission(materialAt(s.material), s.uv, s.frontFacing);
      emitted += unitEmission(e, lightScales[s.lightGroup].rgb) * emissions[s.lightGroup].rgb;
    }
  }
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
  // Each part blended with the pixel's own by the points behind them: its shading has n (and is
  // kept beyond one sample), its seen emission n x the renderer's emission rays per sample.
  const float k = float(traced), ownEmissionPoints = n * float(max(pc.ownEmissionRays, 1u));
  const vec3 ownShading = light[4];
  const vec3 outShading = resolveShading ? (ownShading + shading) / (1.0 + k) : ownShading;
  const vec3 outEmission = (ownEmissionPoints * ownEmission + emitted) / (ownEmissionPoints + k);
  combined[pixel] = vec4(outShading + outEmission, 1.0);
}
