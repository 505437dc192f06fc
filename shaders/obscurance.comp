#version 460
// obscurance.comp — N_obs obscurance rays per primary hit [RTO §4.1 step 3]; accumulates
// A = R(P) W_c (colour bleeding) or R(P) W (grey) and W itself (gatherObscurance, obscurance.glsl);
// with secondary reflectors, the direct light that marked surfaces reflect to P into D_s.
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

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;

void main() {
  gSceneScale = pc.sceneSize;
  BandPixel bp = shadedPixel(); // every pixel of the band, or the dirty ones of a retrace
  if (!bp.inside) return;
  uvec2 p = bp.frame;
  uint pixel = bp.index;
  if (beginProbe() && skipClean(pixel)) return; // a probe: this candidate is dirty already
  GBufferTexel g = gbufferAt(pixel);
  if (g.albedo.a == 0.0) return;

  ShadingPoint sp = shadingPointFromGBuffer(g, pc.eye);
  uint rng = rngSeed(p, pc.sampleIndex, pc.seed ^ 0x9e3779b9u);
  gLightSampling = (pc.renderFlags & kFlagAreaLightSampling) != 0u ? kLightSamplingArea : kLightSamplingSpatial;
  StepBudget budget = newStepBudget();
  // A probe too (not in the macro): N_obs rays at every primary hit.
  uint farRays;
  const vec4 gathered = gatherObscurance(sp, rng, budget, pixel, bp.count, pc.obscuranceRays, farRays);
  OBS_ACCUMULATE_TEXEL(ambient, pixel, gathered)
  if (kProbe) endProbe(pixel);
  else {
    atomicAdd(status[kStatusObscuranceRays], pc.obscuranceRays + farRays);
    // A ray past dMax may pass anywhere: dirty.comp then cannot bound this pixel's rays.
    if (farRays > 0u && (pc.dispatchFlags & kShadeFlagPerLight) == 0u) hitBounds[2u * pixel].w = 1.0;
  }
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
}
