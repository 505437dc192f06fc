#version 460
// specular.comp — specular paths from the glossy primary hits in the queue [RTO §4.1 step 4]:
// follow the specular lobe up to the maximum depth (6, SPEC §1.3); at every vertex reached,
// gather direct light and obscurance as at P, weighted by the path throughput, into the
// specular basis buffers (still linear in every E_s [SPEC §3]).
//
// The primary hit's own direct light (full BSDF) and obscurance (diffuse part) come from
// shadow.comp and obscurance.comp; this pass adds what arrives through the specular lobe.
// Emitters seen through the lobe: after a mirror (delta) bounce they count whole (no light sample
// can find that path); after a glossy bounce, with kFlagGlossyMis, they count with the power
// heuristic against the vertex's N_s light samples (lib/shade.glsl weighs the other side), and
// without it (the paper's estimator, per-light shadow rays) not at all, since the shadow rays
// then take all of that light.
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

void main() {
  gSceneScale = pc.eye.w;
  gLightSampling = (pc.counts.w & kFlagAreaLightSampling) != 0u ? kLightSamplingArea : kLightSamplingSpatial;
  const bool glossyMis = (pc.counts.w & kFlagGlossyMis) != 0u;
  uint entry = gl_GlobalInvocationID.x;
  if (entry >= queue[kQueueCount]) return;
  uint pixel = queue[kQueueHeader + entry];
  uvec2 size = pc.frame.xy;
  BandPixel bp = bandPixelFromIndex(pixel, size, pc.band.xy);
  uvec2 p = bp.frame;
  uint pixelCount = bp.count;
  beginProbe(); // the queue holds only the candidates not yet found dirty (skipClean)
  const uint lightCount = pc.counts.x;
  const uint shadowRays = lightCount > 0u ? pc.counts.y : 0u;
  const uint maxDepth = uint(pc.params.w);
  const bool oneLight = shadesOneLight();
  const uint addedLight = pc.band.w;
  const bool noDirect = (pc.band.z & kShadeFlagNoDirect) != 0u;
  // The frame keeps this sample's rays (the host checks that the depth and N_s fit): the plain
  // kernel writes the lobe hits and the vertices' shadow rays; the variants that follow the paths
  // again (an added light, a probe) take them when specialised with kReplayRays (lib/kept_rays.glsl).
  const bool keepRays = !kProbe && !kPerLight && !kReplayRays && (pc.band.z & kShadeFlagKeptRays) != 0u;

  ShadingPoint sp = shadingPointFromGBuffer(gbuffer[pixel], pc.eye.xyz);
  uint pathRng = rngSeed(p, pc.frame.z, pc.frame.w ^ 0x27d4eb2fu); // lobe samples only
  uint rng = rngSeed(p, pc.frame.z, pc.frame.w ^ 0x6c8e9cf5u);     // what is gathered
  StepBudget budget = newStepBudget();
  vec3 throughput = vec3(1.0);
  uint rays = 0u;
  // The box of this path's vertices, and whether a ray of it left the scene (dirty.comp).
  vec3 pathLo = sp.position, pathHi = sp.position;
  bool escaped = false;
  for (uint depth = 1u; depth < maxDepth && sp.glossy; ++depth) {
    vec3 t, b;
    orthonormalBasis(sp.ns, t, b);
    vec3 wo = vec3(dot(sp.wo, t), dot(sp.wo, b), dot(sp.wo, sp.ns));
    vec3 wiLocal, weight;
    bool delta;
    if (wo.z <= 0.0 || !sampleSpecularLobe(sp, wo, vec2(rngNext(pathRng), rngNext(pathRng)), wiLocal, weight, delta)) break;
    vec3 wi = toWorld(wiLocal, t, b, sp.ns);
    if (dot(wi, sp.ng) <= 0.0) break; // below the geometric surface: no leaks
    // What MIS needs of the vertex the lobe sample leaves (its light samples' density).
    float lobePdf = delta ? 0.0 : ggxReflectionPdf(wo, wiLocal, ggxAlpha(sp.roughness));
    vec3 previous = sp.position, previousNormal = sp.ng;
    throughput *= weight;
    if (all(equal(throughput, vec3(0.0)))) break;
    vec3 origin = offsetRayOrigin(sp.position, sp.ng);
    const uint hitSlot = pathHitSlot(pc.frame.z, pixel, pixelCount, depth);
    RayHit h;
    if (kReplayRays) {
      h = probedPathHit(hitSlot, origin, wi);
    } else {
      h = traceFollowed(budget, origin, wi, 0.0, 1.0 / 0.0); // traced even when probing
      ++rays;
      if (keepRays) keepPathHit(hitSlot, h);
    }
    if (gProbeMet) break; // a probe that met a changed box: the pixel is dirty, the rest is moot
    if (!rayHitValid(h) || h.primitive == kInvalidIndex) {
      escaped = true;
      // The sky along the lobe: whole after a mirror, MIS-weighted after a glossy bounce.
      uint sky = findBackgroundLight(lightCount);
      if ((oneLight && sky != addedLight) || noDirect) sky = kInvalidIndex;
      if (!kProbe && h.primitive != kTruncatedHit && sky != kInvalidIndex && (delta || (glossyMis && !oneLight))) { // a miss, not a truncation
        float w = delta ? 1.0 : powerHeuristic(lobePdf, float(shadowRays) * backgroundLightPdf(sky, previous, previousNormal, lightCount, wi));
        OBS_ACCUMULATE(specularBasis, sky * pixelCount + pixel, vec4(w * throughput, 0.0))
      }
      break;
    }
    Surface s = surfaceAt(h, origin, wi);
    pathLo = min(pathLo, s.position);
    pathHi = max(pathHi, s.position);
    GpuMaterial m = materials[s.material];
    vec3 baseColor = materialBaseColor(m, s.uv).rgb;
    const bool counted = oneLight ? delta && s.lightGroup == addedLight : !noDirect && (delta || glossyMis);
    if (!kProbe && counted && s.lightGroup != kInvalidIndex && s.lightGroup < lightCount) {
      float w = 1.0;
      if (!delta) {
        float lightPdf = emitterHitLightPdf(s.lightGroup, previous, previousNormal, lightCount, h, s.position, wi);
        w = powerHeuristic(lobePdf, float(shadowRays) * lightPdf);
      }
      // Seen emission in unit-emission terms: divided by the group's E_s (1 where E_s is 0).
      vec3 unit = unitEmission(materialEmission(m, s.uv, s.frontFacing), lightScales[s.lightGroup].rgb);
      OBS_ACCUMULATE(specularBasis, s.lightGroup * pixelCount + pixel, vec4(w * throughput * unit, 0.0))
    }
    sp = shadingPoint(s.position, s.geometricNormal, s.shadingNormal, -wi, baseColor, s.material);
    // Gather as at P [RTO §4.1 step 4]: direct light, then obscurance.
    // MIS only where a lobe sample follows from this vertex (the loop goes on past it).
    float misSamples = glossyMis && depth + 1u < maxDepth ? float(shadowRays) : 0.0;
    const vec4 lightShift = rngNext4(rng); // this vertex's light samples: one shifted low-discrepancy set
    if (kProbe && kReplayRays) {
      // The vertex's kept shadow rays (never kept for one light alone, nor without direct light:
      // the host keeps no rays with per-light shadow sampling).
      probeKeptShadowRays(offsetRayOrigin(sp.position, sp.ng), pc.frame.z, pixel, pixelCount, depth, shadowRays);
    } else {
      // A probe whose shafts from the vertex to the lights all miss the boxes draws no light sample.
      const bool drawn = !kProbe || probeShadowRaysMayMeet(sp.position, lightCount);
      if (oneLight) {
        uint taken = 0u;
        vec3 direct = vec3(0.0);
        if (drawn) direct = directLightFromOne(sp, addedLight, lightShift, budget, taken);
        OBS_ACCUMULATE(specularBasis, addedLight * pixelCount + pixel, vec4(throughput * direct, 0.0))
        rays += taken;
        continue;
      }
      for (uint k = 0u; k < (noDirect || !drawn ? 0u : shadowRays); ++k) {
        vec4 u = kroneckerPoint4(k, lightShift);
        vec3 contribution;
        uint light;
        directLightSample(sp, u, lightCount, misSamples, budget, contribution, light);
        if (keepRays) keptShadowRays[keptShadowRaySlot(pc.frame.z, pixel, pixelCount, depth, k)] = gShadowRay;
        OBS_ACCUMULATE(specularBasis, light * pixelCount + pixel, vec4(throughput * contribution / float(shadowRays), 0.0))
      }
    }
    // Secondary reflectors only at primary hits: here the ambient keeps its whole I_a.
    vec4 aw = gatherObscurance(sp, rng, budget, kInvalidIndex, pixelCount);
    OBS_ACCUMULATE(specularAmbient, pixel, vec4(throughput * aw.rgb, 0.0))
    rays += (noDirect ? 0u : shadowRays) + pc.counts.z;
  }
  if (!oneLight && !kProbe) {
    vec4 lo = hitBounds[2u * pixel], hi = hitBounds[2u * pixel + 1u];
    hitBounds[2u * pixel] = vec4(min(lo.xyz, pathLo), max(lo.w, escaped ? 1.0 : 0.0));
    hitBounds[2u * pixel + 1u] = vec4(max(hi.xyz, pathHi), hi.w);
  }
  if (kProbe) endProbe(pixel);
  else atomicAdd(status[kStatusSpecularRays], rays);
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
}
