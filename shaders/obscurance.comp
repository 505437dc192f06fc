#version 460
// obscurance.comp — N_obs cosine-distributed rays per primary hit with tmax = dMax
// [RTO §4.1 step 3], by systematic [RTO §4.2] or independent random sampling:
//   W   = 1/pi  int rho(d) cos dw      ~ mean of rho(d_i)              [RTO eq. 2]
//   W_c = 1/pi  int R(Q) rho(d) cos dw ~ mean of R(Q_i) rho(d_i)        [RTO eq. 6]
// (the cosine pdf cancels the 1/pi cos factor), R(Q) := R_ave on a miss [SPEC §1.2]. Accumulates
// A = R(P) W_c (colour bleeding) or R(P) W (grey) and W itself.
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
#include "lib/shade.glsl"
#include "lib/obscurance.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;

// R(Q): the mean albedo a-bar of the surface hit, times its base-colour texture.
vec3 reflectanceAt(RayHit hit, vec3 origin, vec3 direction) {
  Surface s = surfaceAt(hit, origin, direction);
  GpuMaterial m = materials[s.material];
  vec3 r = m.meanAlbedo.rgb;
  if (m.textures.x >= 0) r *= sampleTexture(m.textures.x, s.uv).rgb;
  return r;
}

void main() {
  uvec2 size = pc.frame.xy;
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= size.x || p.y >= size.y) return;
  uint pixel = p.y * size.x + p.x;
  GBufferTexel g = gbuffer[pixel];
  if (g.albedo.a == 0.0) return;

  ShadingPoint sp = shadingPointFromGBuffer(g, pc.eye.xyz);
  uint rng = rngSeed(p, pc.frame.z, pc.frame.w ^ 0x9e3779b9u);
  vec3 t, b;
  orthonormalBasis(sp.ns, t, b);
  const uint n = pc.counts.z;
  const bool systematic = (pc.counts.w & kFlagSystematic) != 0u;
  const bool bleed = (pc.counts.w & kFlagBleed) != 0u;
  const float dMax = pc.params.x;
  const uint rhoKind = uint(pc.params.z);
  uvec2 grid = systematicGrid(n);
  vec2 offset = vec2(rngNext(rng), rngNext(rng)); // systematic: ONE random pair per hit
  vec3 origin = offsetRayOrigin(sp.position, sp.ng);
  StepBudget budget = newStepBudget();
  float w = 0.0;
  vec3 wc = vec3(0.0);
  for (uint i = 0u; i < n; ++i) {
    vec2 u = systematic ? offset : vec2(rngNext(rng), rngNext(rng));
    vec3 local = systematic ? sampleSystematic(i, grid, offset) : sampleCosineHemisphere(u);
    vec3 direction = toWorld(local, t, b, sp.ns);
    float r = 0.0;       // a direction into the surface is blocked at d = 0 (rho(0) = 0)
    vec3 reflectance = vec3(0.0);
    if (dot(direction, sp.ng) > 0.0) {
      RayHit h = traceWithBudget(budget, origin, direction, 0.0, dMax, false);
      if (rayHitValid(h) && h.primitive != kInvalidIndex) {
        r = rho(h.t, dMax, rhoKind, pc.params.y);
        reflectance = bleed ? reflectanceAt(h, origin, direction) : vec3(0.0);
      } else {
        r = 1.0;
        reflectance = pc.rAve.rgb;
      }
    }
    w += r;
    wc += reflectance * r;
  }
  w /= float(n);
  wc /= float(n);
  vec3 a = obscuranceReflectance(sp) * (bleed ? wc : vec3(w));
  ambient[pixel] += vec4(a, w);
  atomicAdd(status[kStatusObscuranceRays], n);
  if (budget.truncated) atomicAdd(status[kStatusTruncated], 1u);
}
