#version 460
// shadow.comp — direct light at the primary hit: N_s shadow rays per hit [RTO §4.1 step 2],
// each to a light and a point on it chosen by the shared estimator (lib/lights.glsl: by
// importance and solid angle, or the paper's by power and area), accumulated per light into the
// basis buffers D_s at unit emission [SPEC §3]:
//   D_s += f(P, wo, wi) L_e cos(theta_P) / pdf_omega / N_s
// (with MIS weights on a glossy lobe that specular.comp samples too, lib/shade.glsl).
// With kShadeFlagKeptRays the plain kernel keeps each shadow ray (lib/kept_rays.glsl), and the
// probing variant specialised with kReplayRays tests those instead of drawing the light samples.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/shading_bindings.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/ray.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/bsdf.glsl"
#include "lib/lights.glsl"
#include "lib/mis.glsl"
#include "lib/shade.glsl"
#include "lib/accumulate.glsl"
#include "lib/band.glsl"
#include "lib/kept_rays.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;

void main() {
  gSceneScale = pc.sceneSize;
  gLightSampling = (pc.renderFlags & kFlagAreaLightSampling) != 0u ? kLightSamplingArea : kLightSamplingSpatial;
  BandPixel bp = shadedPixel(); // every pixel of the band, or the dirty ones of a retrace
  if (!bp.inside) return;
  uvec2 p = bp.frame;
  uint pixel = bp.index;
  uint pixelCount = bp.count;
  if (beginProbe() && skipClean(pixel)) return; // a probe: this candidate is dirty already
  GBufferTexel g = gbufferAt(pixel);
  if (g.albedo.a == 0.0) return; // no hit: nothing to light

  ShadingPoint sp = shadingPointFromGBuffer(g, pc.eye);
  if (kReplayRays) { // a probe by the kept rays (never for one light alone: those are not kept)
    probeKeptShadowRays(offsetRayOrigin(sp.position, sp.ng), pc.sampleIndex, pixel, pixelCount, 0u, pc.shadowRays);
    endProbe(pixel);
    return;
  }
  // A probe whose shafts from the hit to the lights all miss the boxes draws no light sample.
  const bool drawn = !kProbe || probeShadowRaysMayMeet(sp.position, pc.lightCount);
  if (!drawn) return;
  uint rng = rngSeed(p, pc.sampleIndex, pc.seed ^ 0x5bd1e995u);
  StepBudget budget = newStepBudget();
  const vec4 lightShift = rngNext4(rng); // the hit's light samples: one shifted low-discrepancy set
  if (shadesOneLight()) {
    const uint light = pc.light;
    uint taken;
    vec3 direct = directLightFromOne(sp, light, lightShift, budget, taken);
    OBS_ACCUMULATE_TEXEL(basis, light * pixelCount + pixel, vec4(direct, 0.0))
    if (kProbe) endProbe(pixel);
    else atomicAdd(status[kStatusShadowRays], taken);
    if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
    return;
  }
  uint count = drawn ? pc.shadowRays : 0u;
  const bool keepRays = !kProbe && !kPerLight && (pc.dispatchFlags & kShadeFlagKeptRays) != 0u;
  float invCount = 1.0 / float(count);
  float misSamples = (pc.renderFlags & kFlagGlossyMis) != 0u ? float(count) : 0.0;
  for (uint k = 0u; k < count; ++k) {
    vec4 u = kroneckerPoint4(k, lightShift);
    vec3 contribution;
    uint light;
    directLightSample(sp, u, pc.lightCount, misSamples, budget, contribution, light);
    if (keepRays) keptShadowRays[keptShadowRaySlot(pc.sampleIndex, pixel, pixelCount, 0u, k)] = gShadowRay;
    OBS_ACCUMULATE_TEXEL(basis, light * pixelCount + pixel, vec4(contribution * invCount, 0.0))
  }
  if (kProbe) endProbe(pixel);
  else atomicAdd(status[kStatusShadowRays], count);
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
}
