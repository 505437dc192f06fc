#version 460
// pathtrace.comp — the reference: unbiased path tracing [RTO §5.1, SPEC §1.5], one path per pixel
// per dispatch (dispatch i = sample i), added to a per-pixel radiance sum.
//
// The same scene bindings, traversal, intersection, surface, material, BSDF, light-sampling and
// shadow-ray code as the obscurance passes (lib/*.glsl), so the two methods differ only in the
// light transport they estimate. At each scattering vertex of the path:
//   * emission seen along the ray that reached it (one-sided unless doubleSided, SPEC §5);
//   * next-event estimation: the shared direct-light estimator (lights.glsl sampleLight: light
//     by importance at the vertex and a point by solid angle, or the paper's by power and area),
//     a shadow ray (shade.glsl directLightSample);
//   * one BSDF sample (bsdf.glsl sampleBsdf) continues the path;
// area-light contributions reached by both techniques are combined with the power heuristic
// (Veach & Guibas 1995, lib/mis.glsl); punctual lights (light sampling only) and emitters seen
// through a mirror's delta lobe or by the camera (BSDF sampling only) count fully.
//
// Depth [SPEC §5]: d = maxDepth counts scattering vertices, like pbrt's maxdepth: d = 1 is
// camera -> surface -> light (direct light only); a furnace of albedo a gives
// L_e (1 - a^(d+1)) / (1 - a).
//
// Russian roulette (Pharr, Jakob & Humphreys, "Physically Based Rendering", 3rd ed., §13.7):
// from the rrDepth-th scattering vertex on, the path continues past each vertex with probability
// q = min(max component of the throughput, kRrMaxSurvival), and the throughput is divided by q,
// which keeps the estimator unbiased (E[X/q · 1{survive}] = X). Paths that carry little light
// end early; a surviving path's throughput is lifted back to about 1. OURS: the cap 0.95, so that
// even a white furnace ends its paths (about 20 further vertices on average); rrDepth >= maxDepth
// turns roulette off.
//
// The loop limiter (docs/ARCHITECTURE.md, lavapipe): ONE StepBudget per invocation is shared by
// every traversal of the path (camera, shadow and bounce rays). A truncated traversal ends the
// path where it is (the sample keeps what it gathered so far) and the invocation counts once in
// status[kStatusTruncated], which the host reports and the commands refuse.
//
// Non-finite guard: a sample whose radiance has a NaN or inf component is dropped (adds 0) and
// counted in the .w of its pixel's sum; the host sums those counts (PathTraceResult). The divisor
// stays spp, as pbrt does when it zeroes such samples.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"


#include "lib/scene_bindings.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(push_constant) uniform Push { PathPush pc; };
layout(std430, set = 0, binding = kBindingPathRadiance) buffer RadianceBuffer { vec4 radiance[]; };
#include "lib/light_bindings.glsl" // at kBindingPathLights and kBindingPathEmitters
layout(std430, set = 0, binding = kBindingPathLightTree) readonly buffer LightTreeBuffer { GpuLightNode lightTree[]; };
layout(std430, set = 0, binding = kBindingPathScales) readonly buffer ScaleBuffer { vec4 emissionScale[]; };
layout(std430, set = 0, binding = kBindingPathEmitterEdges) buffer EmitterEdges { uint emitterEdges[]; };

#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/surface.glsl"
#include "lib/material.glsl"
#include "lib/ray.glsl"
#include "lib/rng.glsl"
#include "lib/camera.glsl"
#include "lib/sampling.glsl"
#include "lib/bsdf.glsl"
#include "lib/lights.glsl"
#include "lib/mis.glsl"
#include "lib/shade.glsl"
#include "lib/accumulate.glsl"
#include "lib/band.glsl"
#include "lib/emission_samples.glsl"

// OURS: the largest survival probability of Russian roulette (see the header).
const float kRrMaxSurvival = 0.95;

// Exponent all ones: inf or NaN, tested on the bits so no fast-math assumption can remove it.
bool nonFinite(vec3 v) {
  uvec3 e = (floatBitsToUint(v) >> 23u) & 0xFFu;
  return any(equal(e, uvec3(0xFFu)));
}

float maxComponent(vec3 v) { return max(v.x, max(v.y, v.z)); }

void main() {
  gSceneScale = pc.camera.right.w;
  uvec2 size = uvec2(pc.width, pc.height);
  BandPixel bp = bandPixel(gl_GlobalInvocationID.xy, size, uvec2(pc.firstRow, pc.rows));
  if (!bp.inside) return;
  uvec2 p = bp.frame;
  uint pixel = bp.index;
  const uint lightCount = pc.lightCount;
  const uint maxDepth = pc.maxDepth;
  const uint rrDepth = pc.rrDepth;
  const uint strategy = pc.strategy;
  gLightSampling = pc.lightSampling;
  // --emission-samples K: K > 1 estimates the emission the camera ray sees from K rays of their own
  // (lib/emission_samples.glsl), as the obscurance renderer's M_s does; the path's vertex 1 then
  // adds none.
  const uint emissionSamples = min(pc.emissionSamples, kMaxEmissionSamples);
  bool ownEmissionRays = emissionSamples > 1u;

  // The camera ray exactly as primary.comp makes it: the same per-pixel shift of the same R2
  // sub-pixel sequence, so sample i of both renderers goes through the same point of the pixel.
  uint rng = rngSeed(p, 0u, pc.seed);
  vec2 shift = vec2(rngNext(rng), rngNext(rng));
  vec2 position = vec2(p) + pixelSampleOffset(pc.sampleIndex, shift);
  vec3 origin = pc.camera.origin.xyz;
  vec3 direction = cameraRayDirection(pc.camera, position, vec2(size));
  // The path's own stream (a constant of ours keeps it apart from the shading passes' streams).
  rng = rngSeed(p, pc.sampleIndex, pc.seed ^ 0x27d4eb2fu);

  StepBudget budget = newStepBudget();
  uint rays = 1u;
  RayHit hit = traceWithBudget(budget, origin, direction, 0.0, 1.0 / 0.0, false);
  // --emission-samples auto: the K rays only where an emitter's edge crosses the pixel, as
  // primary.comp decides it (lightCount 0: nothing emits with power).
  if (ownEmissionRays && pc.emissionAtEdges != 0u) {
    uint probeRays;
    ownEmissionRays = emissionRaysAtEdge(budget, pc.camera, p, vec2(size), lightCount, pixel,
                                         pc.sampleIndex == pc.firstSample, probeRays);
    rays += probeRays;
  }

  vec3 L = vec3(0.0);
  if (ownEmissionRays) {
    uint sky = floatBitsToUint(pc.camera.up.w);
    for (uint j = 0u; j < emissionSamples; ++j) {
      SeenEmitter e = traceEmissionSample(budget, pc.camera, p, vec2(size), pc.sampleIndex, j, emissionSamples, shift, lightCount);
      L += (e.sky ? emissionScale[sky].rgb : e.radiance) / float(emissionSamples);
    }
    rays += emissionSamples;
  }
  vec3 beta = vec3(1.0);        // path throughput: f cos / pdf products (and 1/q of roulette)
  bool specularBounce = true;   // the ray came from the camera or a mirror's delta lobe
  float bsdfPdfPrev = 0.0;      // solid-angle pdf of the BSDF sample that made the ray
  vec3 previous = origin;       // the vertex the ray left from
  vec3 previousNormal = vec3(0.0); // its geometric normal (light selection depends on it)

  // Vertex `depth` (1 = the camera ray's hit): its emission ends a path of depth - 1 scattering
  // vertices, its scattering (light sample, BSDF sample) makes depth of them.
  for (uint depth = 1u; depth <= maxDepth + 1u; ++depth) {
    if (hit.primitive == kInvalidIndex || !rayHitValid(hit)) {
      // A miss sees the sky, when there is one (camera.up.w: its slot); a truncated ray nothing.
      uint sky = floatBitsToUint(pc.camera.up.w);
      if (hit.primitive != kTruncatedHit && sky < lightCount) { // a miss, not a truncation
        float w = 1.0;
        if (!specularBounce && strategy != kPathStrategyBsdfOnly) {
          float lightPdf = backgroundLightPdf(sky, previous, previousNormal, lightCount, direction);
          w = strategy == kPathStrategyLightOnly ? (lightPdf > 0.0 ? 0.0 : 1.0) : powerHeuristic(bsdfPdfPrev, lightPdf);
        }
        if (!(depth == 1u && ownEmissionRays)) L += beta * w * emissionScale[sky].rgb;
      }
      break;
    }
    Surface s = surfaceAt(hit, origin, direction);
    GpuMaterial m = materialAt(s.material);

    // ---- Emission seen along the ray [SPEC §5: one-sided unless doubleSided].
    vec3 emitted = materialEmission(m, s.uv, s.frontFacing);
    if (any(greaterThan(emitted, vec3(0.0))) && !(depth == 1u && ownEmissionRays)) {
      float w = 1.0;
      if (!specularBounce && s.lightGroup < lightCount && strategy != kPathStrategyBsdfOnly) {
        // This point could also have come from sampleLight at the previous vertex [MIS].
        float lightPdf = emitterHitLightPdf(s.lightGroup, previous, previousNormal, lightCount, hit, s.position, direction);
        w = strategy == kPathStrategyLightOnly ? (lightPdf > 0.0 ? 0.0 : 1.0)
                                               : powerHeuristic(bsdfPdfPrev, lightPdf);
      }
      L += beta * w * emitted;
    }
    if (depth > maxDepth) break;

    // ---- The shading point. Reflection is two-sided [SPEC §5]: the shading normal is turned to
    // the side of wo, so wo lies in the upper hemisphere of the BSDF's local frame (the geometric
    // normal already faces the ray, surface.glsl).
    vec3 wo = -direction;
    vec3 ns = dot(s.shadingNormal, wo) < 0.0 ? -s.shadingNormal : s.shadingNormal;
    vec3 baseColor = materialBaseColor(m, s.uv).rgb;
    ShadingPoint sp = shadingPoint(s.position, s.geometricNormal, ns, wo, baseColor, s.material);
    vec3 t, b;
    orthonormalBasis(sp.ns, t, b);
    vec3 woLocal = vec3(dot(wo, t), dot(wo, b), dot(wo, sp.ns));

    // ---- Next-event estimation: one light sample, one shadow ray.
    vec4 uLight = vec4(rngNext(rng), rngNext(rng), rngNext(rng), rngNext(rng));
    if (lightCount > 0u) {
      // sampleLight is deterministic in (p, u): this is the sample directLightSample draws below;
      // drawing it first gives its pdf for the MIS weight and skips shadow rays of weight 0.
      LightSample ls = sampleLight(sp.position, sp.ng, uLight, lightCount);
      bool area = ls.hittable; // an area light or the sky: BSDF sampling reaches it too
      float w = 1.0;
      if (area && strategy == kPathStrategyBsdfOnly) {
        w = 0.0;
      } else if (area && strategy == kPathStrategyMis) {
        vec3 wiLocal = vec3(dot(ls.wi, t), dot(ls.wi, b), dot(ls.wi, sp.ns));
        w = powerHeuristic(ls.pdf, bsdfPdf(sp.baseColor, sp.metallic, sp.roughness, woLocal, wiLocal));
      }
      if (w > 0.0 && any(greaterThan(ls.weight, vec3(0.0)))) {
        vec3 contribution; // unit emission; x E_s below
        uint light;
        uint tracedBefore = budget.traced;
        directLightSample(sp, uLight, lightCount, 0.0, budget, contribution, light);
        if (budget.traced != tracedBefore) rays++; // it traced a shadow ray
        L += beta * w * emissionScale[light].rgb * contribution;
      }
      if (budget.truncated) break;
    }

    // ---- BSDF sampling continues the path.
    vec3 uBsdf = vec3(rngNext(rng), rngNext(rng), rngNext(rng));
    float uRr = rngNext(rng);
    vec3 wiLocal;
    float pdf;
    bool delta;
    vec3 weight = sampleBsdf(sp.baseColor, sp.metallic, sp.roughness, woLocal, uBsdf, wiLocal, pdf, delta);
    if (pdf <= 0.0) break;
    vec3 wi = toWorld(wiLocal, t, b, sp.ns);
    if (dot(wi, sp.ng) <= 0.0) break; // below the geometric surface: no light reflects that way
    beta *= weight;
    if (depth >= rrDepth) {
      float q = min(maxComponent(beta), kRrMaxSurvival);
      if (!(uRr < q)) break;
      beta /= q;
    }
    specularBounce = delta;
    bsdfPdfPrev = pdf;
    previous = s.position;
    previousNormal = sp.ng;
    origin = offsetRayOrigin(s.position, sp.ng);
    direction = wi;
    hit = traceWithBudget(budget, origin, direction, 0.0, 1.0 / 0.0, false);
    rays++;
  }

  // A non-finite sample is dropped and counted in .w (see the header).
  OBS_ACCUMULATE(radiance, pixel, nonFinite(L) ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(L, 0.0))
  atomicAdd(status[kStatusPathRays], rays);
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
}
