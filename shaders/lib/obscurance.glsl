// obscurance.glsl — rho(d) and the obscurance estimate at a shading point [RTO §3, eqs. 2 and
// 6; SPEC §1.1-1.2], shared by obscurance.comp (primary hits) and specular.comp (path vertices).
// Needs the scene and shading bindings, bvh.glsl, surface.glsl, material.glsl, ray.glsl,
// rng.glsl, sampling.glsl and shade.glsl.
#ifndef OBSCURA_OBSCURANCE_GLSL
#define OBSCURA_OBSCURANCE_GLSL

// rho(d) for d < dMax; rho = 1 from dMax on (a miss within dMax).
float rho(float d, float dMax, uint kind, float tau) {
  float x = clamp(d / dMax, 0.0, 1.0);
  if (kind == kRhoAo) return x >= 1.0 ? 1.0 : 0.0;
  // OURS: normalised so rho(dMax) = 1 [SPEC §1.1].
  if (kind == kRhoExp) return (1.0 - exp(-tau * x)) / (1.0 - exp(-tau));
  return sqrt(x); // the paper's choice
}

// R(Q): the mean albedo a-bar of the surface hit, times its base-colour texture.
vec3 reflectanceAt(RayHit hit, vec3 origin, vec3 direction) {
  Surface s = surfaceAt(hit, origin, direction);
  GpuMaterial m = materials[s.material];
  vec3 r = m.meanAlbedo.rgb;
  if (m.textures.x >= 0) r *= sampleTexture(m.textures.x, s.uv).rgb;
  return r;
}

// N_obs cosine-distributed rays around the shading normal with tmax = dMax, by systematic
// [RTO §4.2] or independent sampling:
//   W   = 1/pi  int rho(d) cos dw      ~ mean of rho(d_i)              [RTO eq. 2]
//   W_c = 1/pi  int R(Q) rho(d) cos dw ~ mean of R(Q_i) rho(d_i)        [RTO eq. 6]
// (the cosine pdf cancels the 1/pi cos factor), R(Q) := R_ave on a miss [SPEC §1.2].
// Returns (A, W) with A = R(P) W_c (colour bleeding) or R(P) W (grey).
vec4 gatherObscurance(ShadingPoint sp, inout uint rng, inout StepBudget budget) {
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
  float w = 0.0;
  vec3 wc = vec3(0.0);
  for (uint i = 0u; i < n; ++i) {
    vec2 u = systematic ? offset : vec2(rngNext(rng), rngNext(rng));
    vec3 local = systematic ? sampleSystematic(i, grid, offset) : sampleCosineHemisphere(u);
    vec3 direction = toWorld(local, t, b, sp.ns);
    float r = 0.0; // a direction into the surface is blocked at d = 0 (rho(0) = 0)
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
  float invN = 1.0 / float(max(n, 1u));
  w *= invN;
  wc *= invN;
  return vec4(obscuranceReflectance(sp) * (bleed ? wc : vec3(w)), w);
}

#endif
