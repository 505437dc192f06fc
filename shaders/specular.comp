#version 460
// specular.comp — specular paths from the glossy primary hits in the queue [RTO §4.1 step 4]:
// follow the specular lobe up to the maximum depth (6, SPEC §1.3); at every vertex reached,
// gather direct light and obscurance as at P, weighted by the path throughput, into the
// specular basis buffers (still linear in every E_s [SPEC §3]).
//
// A dispatch runs ONE vertex of every path in its depth's queue; the paths that go on are stored
// (storePath) and queued for the next depth, one dispatch each (specular_pass.cpp). A path keeps
// its own generators, so its value does not depend on where or when its vertices run.
//
// The primary hit's own direct light (full BSDF) and obscurance (diffuse part) come from
// shadow.comp and obscurance.comp; this pass adds what arrives through the specular lobe.
// Emitters seen through the lobe: after a mirror (delta) bounce they count whole (no light sample
// can find that path); after a glossy bounce, with kFlagGlossyMis, they count with the power
// heuristic against the vertex's N_s light samples (lib/shade.glsl weighs the other side), and
// without it (the paper's estimator, per-light shadow rays) not at all, since the shadow rays
// then take all of that light.
//
// Every vertex gathers with N_s shadow and N_obs obscurance rays, or with
// kFlagVertexRaysByThroughput (the default) with those counts scaled by the path's throughput
// there (raysAtVertex): a vertex seen through a dielectric's Fresnel reflection (a few per cent)
// adds little to its pixel, and one ray of each kind does for it. A metal vertex reflects none of
// the ambient and traces no obscurance ray.
//
// With kShadeFlagPerLight (a light just added, band.w) the same paths are followed again: the
// lobe samples draw from a generator of their own, so the path of a sample does not depend on
// what is gathered along it. Only that light is gathered, alone as in shadow.comp (no MIS, its
// emission counted after mirror bounces only), and the hit box is left as it was. With
// kShadeFlagNoDirect no light is gathered (those per-light dispatches do it), only the ambient.
// With kShadeFlagProbe (a geometry edit's dirty test, lib/probe.glsl) the same paths are followed
// in the edited scene: the lobe rays are traced, every other ray only tested against the changed
// boxes, nothing is summed, and the pixel is marked dirty when one meets a box.
// With kShadeFlagKeptRays the frame keeps this sample's lobe hits and its vertices' shadow rays:
// the plain kernel writes them, and the per-light and probing variants specialised with kReplayRays
// read them instead of tracing the lobe rays and drawing the probed light samples again
// (lib/kept_rays.glsl).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/shading_bindings.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/surface.glsl"
#include "lib/material.glsl"
#include "lib/ray.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/bsdf.glsl"
#include "lib/lights.glsl"
#include "lib/mis.glsl"
#include "lib/shade.glsl"
#include "lib/accumulate.glsl"
#include "lib/obscurance.glsl"
#include "lib/band.glsl"
#include "lib/kept_rays.glsl"
#include "lib/queue_append.glsl"

layout(local_size_x = kWorkgroupSize1D) in;

// One sample of the specular lobe alone, in the local frame (z = shading normal): GGX visible
// normals (Heitz 2018), whose weight f cos / pdf is F G2 / G1; a mirror below kMirrorRoughness.
bool sampleSpecularLobe(ShadingPoint sp, vec3 wo, vec2 u, out vec3 wi, out vec3 weight, out bool delta) {
  vec3 f0 = mix(vec3(kDielectricF0), sp.baseColor, sp.metallic);
  delta = isMirror(sp.roughness);
  vec3 h = vec3(0.0, 0.0, 1.0);
  float alpha = ggxAlpha(sp.roughness);
  if (!delta) h = sampleGgxVisibleNormal(wo, alpha, u);
  wi = reflect(-wo, h);
  float cosOH = max(dot(wo, h), 0.0);
  vec3 fresnel = fresnelSchlick(f0, cosOH);
  if (wi.z <= 0.0) { weight = vec3(0.0); return false; }
  weight = delta ? fresnel : fresnel * (smithG2(wo.z, wi.z, alpha) / smithG1(wo.z, alpha));
  return true;
}

// What a path carries from one vertex to the next. The pass runs one vertex per dispatch, and
// the paths that go on are queued for the next (a wavefront; Laine, Karras & Aila 2013): with a
// whole path per invocation, lavapipe ran every 8-lane group until its longest path ended, and a
// quarter of the lane-iterations were idle.
struct PathState {
  ShadingPoint sp;
  vec3 throughput;
  uint pathRng;   // lobe samples only
  uint rng;       // what is gathered
  vec3 pathLo;    // the box of the path's vertices (dirty.comp)
  vec3 pathHi;
  bool escaped;   // a ray of the path left the scene or reached past dMax (dirty.comp: unbounded)
  bool truncated; // a traversal of the path ran out of loop passes
  uint pixel;     // band-local
};

// The pass's constants, from the push constants.
struct SpecularConstants {
  uint pixelCount;
  uint lightCount;
  uint shadowRays;
  uint maxDepth;
  bool oneLight;
  uint addedLight;
  bool noDirect;
  bool glossyMis;
  bool raysByThroughput; // kFlagVertexRaysByThroughput
  // The frame keeps this sample's rays (the host checks that the depth and N_s fit): the plain
  // kernel writes the lobe hits and the vertices' shadow rays; the variants that follow the paths
  // again (an added light, a probe) take them when specialised with kReplayRays (lib/kept_rays.glsl).
  bool keepRays;
};

SpecularConstants specularConstants() {
  SpecularConstants c;
  c.pixelCount = pc.width * pc.rows;
  c.lightCount = pc.lightCount;
  c.shadowRays = c.lightCount > 0u ? pc.shadowRays : 0u;
  c.maxDepth = uint(pc.maxDepth);
  c.oneLight = shadesOneLight();
  c.addedLight = pc.light;
  c.noDirect = (pc.dispatchFlags & kShadeFlagNoDirect) != 0u;
  c.glossyMis = (pc.renderFlags & kFlagGlossyMis) != 0u;
  c.raysByThroughput = (pc.renderFlags & kFlagVertexRaysByThroughput) != 0u;
  c.keepRays = !kProbe && !kPerLight && !kReplayRays && (pc.dispatchFlags & kShadeFlagKeptRays) != 0u;
  return c;
}

// The rays of one kind a vertex gathers with, of `perHit` at a primary hit. By throughput: the
// vertex's estimate reaches its pixel weighted by the path throughput t, so its n rays add
// t^2 sigma^2 / n to the pixel's variance at a cost of n rays; over the vertices, the allocation
// n ~ t (times sigma, alike here) minimises the variance for the rays spent (Neyman allocation
// of a stratified estimator). OURS: n = ceil(perHit max(t)), at least 1, at most perHit; a
// dielectric's Fresnel reflection (t of a few per cent) takes one ray, a metal's nearly all.
// Any n >= 1 leaves the estimate's mean as it is.
uint raysAtVertex(SpecularConstants c, uint perHit, vec3 throughput) {
  if (!c.raysByThroughput || perHit == 0u) return perHit;
  const float share = max(throughput.x, max(throughput.y, throughput.z));
  return clamp(uint(ceil(float(perHit) * share)), 1u, perHit);
}

PathState startPath(SpecularConstants c, uint pixel) {
  BandPixel bp = bandPixelFromIndex(pixel, uvec2(pc.width, pc.height), uvec2(pc.firstRow, pc.rows));
  PathState path;
  path.sp = shadingPointFromGBuffer(gbufferAt(pixel), pc.eye);
  path.throughput = vec3(1.0);
  path.pathRng = rngSeed(bp.frame, pc.sampleIndex, pc.seed ^ 0x27d4eb2fu);
  path.rng = rngSeed(bp.frame, pc.sampleIndex, pc.seed ^ 0x6c8e9cf5u);
  path.pathLo = path.sp.position;
  path.pathHi = path.sp.position;
  path.escaped = false;
  path.truncated = false;
  path.pixel = pixel;
  return path;
}

// The path's vertex at `depth`: its lobe ray from the previous vertex, the emitter it may see,
// then direct light and obscurance gathered there. False when the path ends (no lobe sample, a
// miss, a probe that met a box); `rays` counts the rays traced.
bool followVertex(SpecularConstants c, inout PathState path, uint depth, inout StepBudget budget, inout uint rays) {
  const uint pixel = path.pixel;
  ShadingPoint sp = path.sp;
  vec3 t, b;
  orthonormalBasis(sp.ns, t, b);
  vec3 wo = vec3(dot(sp.wo, t), dot(sp.wo, b), dot(sp.wo, sp.ns));
  vec3 wiLocal, weight;
  bool delta;
  if (wo.z <= 0.0 || !sampleSpecularLobe(sp, wo, vec2(rngNext(path.pathRng), rngNext(path.pathRng)), wiLocal, weight, delta)) return false;
  vec3 wi = toWorld(wiLocal, t, b, sp.ns);
  if (dot(wi, sp.ng) <= 0.0) return false; // below the geometric surface: no leaks
  // What MIS needs of the vertex the lobe sample leaves: its lobe's density, and how many light
  // samples it drew (as many as its throughput gave it, below; shadow.comp's at the primary hit).
  float lobePdf = delta ? 0.0 : ggxReflectionPdf(wo, wiLocal, ggxAlpha(sp.roughness));
  const float vertexLightSamples = float(raysAtVertex(c, c.shadowRays, path.throughput));
  vec3 previous = sp.position, previousNormal = sp.ng;
  path.throughput *= weight;
  const vec3 throughput = path.throughput;
  if (all(equal(throughput, vec3(0.0)))) return false;
  vec3 origin = offsetRayOrigin(sp.position, sp.ng);
  const uint hitSlot = pathHitSlot(pc.sampleIndex, pixel, c.pixelCount, depth);
  RayHit h;
  if (kReplayRays) {
    h = probedPathHit(hitSlot, origin, wi);
  } else {
    h = traceFollowed(budget, origin, wi, 0.0, 1.0 / 0.0); // traced even when probing
    ++rays;
    if (c.keepRays) keepPathHit(hitSlot, h);
  }
  if (gProbeMet) return false; // a probe that met a changed box: the pixel is dirty, the rest is moot
  if (!rayHitValid(h) || h.primitive == kInvalidIndex) {
    path.escaped = true;
    // The sky along the lobe: whole after a mirror, MIS-weighted after a glossy bounce.
    uint sky = findBackgroundLight(c.lightCount);
    if ((c.oneLight && sky != c.addedLight) || c.noDirect) sky = kInvalidIndex;
    if (!kProbe && h.primitive != kTruncatedHit && sky != kInvalidIndex && (delta || (c.glossyMis && !c.oneLight))) { // a miss, not a truncation
      float w = delta ? 1.0 : powerHeuristic(lobePdf, vertexLightSamples * backgroundLightPdf(sky, previous, previousNormal, c.lightCount, wi));
      OBS_ACCUMULATE_TEXEL(specularBasis, sky * c.pixelCount + pixel, vec4(w * throughput, 0.0))
    }
    return false;
  }
  Surface s = surfaceAt(h, origin, wi);
  path.pathLo = min(path.pathLo, s.position);
  path.pathHi = max(path.pathHi, s.position);
  GpuMaterial m = materialAt(s.material);
  vec3 baseColor = materialBaseColor(m, s.uv).rgb;
  const bool counted = c.oneLight ? delta && s.lightGroup == c.addedLight : !c.noDirect && (delta || c.glossyMis);
  if (!kProbe && counted && s.lightGroup != kInvalidIndex && s.lightGroup < c.lightCount) {
    float w = 1.0;
    if (!delta) {
      float lightPdf = emitterHitLightPdf(s.lightGroup, previous, previousNormal, c.lightCount, h, s.position, wi);
      w = powerHeuristic(lobePdf, vertexLightSamples * lightPdf);
    }
    // Seen emission in unit-emission terms: divided by the group's E_s (1 where E_s is 0).
    vec3 unit = unitEmission(materialEmission(m, s.uv, s.frontFacing), lightScales[s.lightGroup].rgb);
    OBS_ACCUMULATE_TEXEL(specularBasis, s.lightGroup * c.pixelCount + pixel, vec4(w * throughput * unit, 0.0))
  }
  sp = shadingPoint(s.position, s.geometricNormal, s.shadingNormal, -wi, baseColor, s.material);
  path.sp = sp;
  // Gather as at P [RTO §4.1 step 4]: direct light, then obscurance.
  const uint shadowRays = raysAtVertex(c, c.shadowRays, throughput);
  // A metal vertex reflects none of the ambient (R(P) = 0, lib/shade.glsl): no obscurance ray.
  const bool reflectsAmbient = any(greaterThan(obscuranceReflectance(sp), vec3(0.0)));
  const uint obscuranceRays = reflectsAmbient ? raysAtVertex(c, pc.obscuranceRays, throughput) : 0u;
  // MIS only where a lobe sample follows from this vertex (the path goes on past it).
  float misSamples = c.glossyMis && depth + 1u < c.maxDepth ? float(shadowRays) : 0.0;
  const vec4 lightShift = rngNext4(path.rng); // this vertex's light samples: one shifted low-discrepancy set
  if (kProbe && kReplayRays) {
    // The vertex's kept shadow rays (never kept for one light alone, nor without direct light:
    // the host keeps no rays with per-light shadow sampling).
    probeKeptShadowRays(offsetRayOrigin(sp.position, sp.ng), pc.sampleIndex, pixel, c.pixelCount, depth, shadowRays);
  } else {
    // A probe whose shafts from the vertex to the lights all miss the boxes draws no light sample.
    const bool drawn = !kProbe || probeShadowRaysMayMeet(sp.position, c.lightCount);
    if (c.oneLight) {
      uint taken = 0u;
      vec3 direct = vec3(0.0);
      if (drawn) direct = directLightFromOne(sp, c.addedLight, lightShift, budget, taken);
      OBS_ACCUMULATE_TEXEL(specularBasis, c.addedLight * c.pixelCount + pixel, vec4(throughput * direct, 0.0))
      rays += taken;
      return true; // one light's rays alone: no obscurance
    }
    for (uint k = 0u; k < (c.noDirect || !drawn ? 0u : shadowRays); ++k) {
      vec4 u = kroneckerPoint4(k, lightShift);
      vec3 contribution;
      uint light;
      directLightSample(sp, u, c.lightCount, misSamples, budget, contribution, light);
      if (c.keepRays) keptShadowRays[keptShadowRaySlot(pc.sampleIndex, pixel, c.pixelCount, depth, k)] = gShadowRay;
      OBS_ACCUMULATE_TEXEL(specularBasis, light * c.pixelCount + pixel, vec4(throughput * contribution / float(shadowRays), 0.0))
    }
  }
  // Secondary reflectors only at primary hits: here the ambient keeps its whole I_a.
  uint farRays;
  vec4 aw = gatherObscurance(sp, path.rng, budget, kInvalidIndex, c.pixelCount, obscuranceRays, farRays);
  OBS_ACCUMULATE_TEXEL(specularAmbient, pixel, vec4(throughput * aw.rgb, 0.0))
  if (farRays > 0u) path.escaped = true; // a ray past dMax may pass anywhere (dirty.comp)
  rays += (c.noDirect ? 0u : shadowRays) + obscuranceRays + farRays;
  return true;
}

// A path that has ended: the box of its vertices for dirty.comp, a probe's verdict, a truncation.
void finishPath(SpecularConstants c, PathState path) {
  const uint pixel = path.pixel;
  if (!c.oneLight && !kProbe) {
    vec4 lo = hitBounds[2u * pixel], hi = hitBounds[2u * pixel + 1u];
    hitBounds[2u * pixel] = vec4(min(lo.xyz, path.pathLo), max(lo.w, path.escaped ? 1.0 : 0.0));
    hitBounds[2u * pixel + 1u] = vec4(max(hi.xyz, path.pathHi), hi.w);
  }
  endProbe(pixel); // a path goes on only while its probe has met no box (gProbeMet)
  if (path.truncated) atomicAdd(status[kStatusTruncated], 1u);
}

// A path's state in specularPaths[kSpecularPathTexels * pixel ...] (the pixel is its index; the
// shading point's material parameters are read again, as shadingPoint reads them).
void storePath(PathState path) {
  const uint at = kSpecularPathTexels * path.pixel;
  const uint flags = (path.escaped ? 1u : 0u) | (path.truncated ? 2u : 0u);
  specularPaths[at] = vec4(path.sp.position, path.throughput.x);
  specularPaths[at + 1u] = vec4(path.sp.ng, path.throughput.y);
  specularPaths[at + 2u] = vec4(path.sp.ns, path.throughput.z);
  specularPaths[at + 3u] = vec4(path.sp.wo, uintBitsToFloat(path.sp.material));
  specularPaths[at + 4u] = vec4(path.sp.baseColor, uintBitsToFloat(flags));
  specularPaths[at + 5u] = vec4(path.pathLo, uintBitsToFloat(path.pathRng));
  specularPaths[at + 6u] = vec4(path.pathHi, uintBitsToFloat(path.rng));
}

PathState loadPath(uint pixel) {
  const uint at = kSpecularPathTexels * pixel;
  vec4 t0 = specularPaths[at], t1 = specularPaths[at + 1u], t2 = specularPaths[at + 2u], t3 = specularPaths[at + 3u];
  vec4 t4 = specularPaths[at + 4u], t5 = specularPaths[at + 5u], t6 = specularPaths[at + 6u];
  const uint flags = floatBitsToUint(t4.w);
  PathState path;
  path.sp = shadingPoint(t0.xyz, t1.xyz, t2.xyz, t3.xyz, t4.xyz, floatBitsToUint(t3.w));
  path.throughput = vec3(t0.w, t1.w, t2.w);
  path.pathRng = floatBitsToUint(t5.w);
  path.rng = floatBitsToUint(t6.w);
  path.pathLo = t5.xyz;
  path.pathHi = t6.xyz;
  path.escaped = (flags & 1u) != 0u;
  path.truncated = (flags & 2u) != 0u;
  path.pixel = pixel;
  return path;
}

// One vertex (depth pc.pathDepth) of each path in this depth's queue.
void main() {
  gSceneScale = pc.sceneSize;
  gLightSampling = (pc.renderFlags & kFlagAreaLightSampling) != 0u ? kLightSamplingArea : kLightSamplingSpatial;
  const SpecularConstants c = specularConstants();
  const uint depth = uint(pc.pathDepth);
  const uint queued = specularQueueBase(depth, c.pixelCount);
  const uint entry = gl_GlobalInvocationID.x;
  if (entry >= queue[queued + kQueueCount]) return;
  const uint pixel = queue[queued + kQueueHeader + entry];
  beginProbe(); // the queue holds only the candidates not yet found dirty (skipClean)
  StepBudget budget = newStepBudget();
  PathState path = depth == 1u ? startPath(c, pixel) : loadPath(pixel);
  uint rays = 0u;
  bool goesOn = false;
  if (depth < c.maxDepth && path.sp.glossy) {
    goesOn = followVertex(c, path, depth, budget, rays);
    path.truncated = path.truncated || budget.truncated;
  }
  if (goesOn && depth + 1u < c.maxDepth && path.sp.glossy) {
    storePath(path);
    OBS_QUEUE_APPEND(queue, specularQueueBase(depth + 1u, c.pixelCount), pixel)
  } else {
    finishPath(c, path);
  }
  if (!kProbe && rays > 0u) atomicAdd(status[kStatusSpecularRays], rays);
}
