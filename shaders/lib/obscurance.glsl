// obscurance.glsl — rho(d) and the obscurance estimate at a shading point [RTO §3, eqs. 2 and
// 6; SPEC §1.1-1.2], shared by obscurance.comp (primary hits) and specular.comp (path vertices).
// Needs the scene and shading bindings, bvh.glsl, surface.glsl, material.glsl, ray.glsl,
// rng.glsl, sampling.glsl, shade.glsl and accumulate.glsl (reflectors write D_s).
#ifndef OBSCURA_OBSCURANCE_GLSL
#define OBSCURA_OBSCURANCE_GLSL

// The variant of a kernel that gathers the secondary reflectors' light (kSpecConstantReflectors):
// without it the reflectors' branch, with a light sample and a second traversal inlined, is not
// compiled in at all; lavapipe's register allocation over the whole shader made the obscurance
// rays' traversal loop 1.7x slower with it present but never taken.
layout(constant_id = kSpecConstantReflectors) const bool kReflectors = false;
// The variant for grey obscurance (kSpecConstantGreyObscurance): no colour bleeding, so neither the
// surface nor the texture at an obscurance ray's hit is looked up.
layout(constant_id = kSpecConstantGreyObscurance) const bool kGreyObscurance = false;

// rho(d) for d < dMax; rho = 1 from dMax on (a miss within dMax).
float rho(float d, float dMax, uint kind, float tau) {
  float x = clamp(d / dMax, 0.0, 1.0);
  if (kind == kRhoAo) return x >= 1.0 ? 1.0 : 0.0;
  // OURS: normalised so rho(dMax) = 1 [SPEC §1.1].
  if (kind == kRhoExp) return (1.0 - exp(-tau * x)) / (1.0 - exp(-tau));
  return sqrt(x); // the paper's choice
}

// R(Q): the mean albedo a-bar of the surface hit, times its base-colour texture.
vec3 reflectanceAt(Surface s) {
  GpuMaterial m = materialAt(s.material);
  vec3 r = m.meanAlbedo.rgb;
  if (kBaseColorTextures && m.textures.x >= 0) r *= sampleTexture(m.textures.x, s.uv).rgb;
  return r;
}

// An important secondary reflector [RTO §2.2 and §6; SPEC §1.6]: the light that Q, hit by an
// obscurance ray from P, reflects of its own direct light, one light sample and one shadow ray
// (the shared estimator, shade.glsl), at unit emission of the light it chose:
//   L(P <- Q) = f(Q, -w, wi) L_e cos / pdf, and with P's cosine-distributed ray, R(P) L / N_obs.
void reflectedDirectLight(Surface s, vec3 direction, vec4 u, inout StepBudget budget, out vec3 contribution,
                          out uint light) {
  vec3 wo = -direction;
  vec3 ns = dot(s.shadingNormal, wo) < 0.0 ? -s.shadingNormal : s.shadingNormal;
  GpuMaterial m = materialAt(s.material);
  ShadingPoint q = shadingPoint(s.position, s.geometricNormal, ns, wo, materialBaseColor(m, s.uv).rgb, s.material);
  directLightSample(q, u, pc.lightCount, 0.0, budget, contribution, light);
}

// n cosine-distributed rays (N_obs at a primary hit; a specular path's vertex may take fewer,
// specular.comp) around the shading normal with tmax = dMax, by systematic [RTO §4.2] or
// independent sampling:
//   W   = 1/pi  int rho(d) cos dw      ~ mean of rho(d_i)              [RTO eq. 2]
//   W_c = 1/pi  int R(Q) rho(d) cos dw ~ mean of R(Q_i) rho(d_i)        [RTO eq. 6]
// (the cosine pdf cancels the 1/pi cos factor), R(Q) := R_ave on a miss [SPEC §1.2]. With
// kFlagDarkEscapes (OURS) a miss within dMax is traced on, and one that leaves the scene adds
// nothing to A (rho R(Q) := 0): the ambient model's light comes from the scene's surfaces, and
// beyond the last of them there are none. `farRays` counts those rays (the caller counts them
// and marks the pixel's hit bounds: they reach past dMax).
// Returns (A, W) with A = R(P) W_c (colour bleeding) or R(P) W (grey).
//
// With secondary reflectors (`reflectorPixel` a pixel, not kInvalidIndex, and the flag set), a
// ray that lands on a marked triangle adds R(P) x Q's reflected direct light to D_s of the light
// sampled there (the basis buffer, [light][pixel] of `pixelCount`), and Q's ambient keeps the
// share kappa of I_a that lies beyond the first bounce; an unmarked Q within dmax keeps
// kappa + r (1 - kappa) (OURS: the paper adds a ray to the light without saying how the two
// combine; these shares keep the first bounce from being counted twice and are constants of the
// render, so I_a stays linear in every emission; secondary_reflectors.h).
vec4 gatherObscurance(ShadingPoint sp, inout uint rng, inout StepBudget budget, uint reflectorPixel, uint pixelCount,
                      uint n, out uint farRays) {
  const bool darkEscapes = (pc.renderFlags & kFlagDarkEscapes) != 0u;
  farRays = 0u;
  const bool systematic = (pc.renderFlags & kFlagSystematic) != 0u;
  const bool bleed = !kGreyObscurance && (pc.renderFlags & kFlagBleed) != 0u;
  const bool reflectors = kReflectors && reflectorPixel != kInvalidIndex && (pc.renderFlags & kFlagSecondaryReflectors) != 0u;
  const float dMax = pc.dMax;
  const uint rhoKind = uint(pc.rhoKind);
  uvec2 grid = systematicGrid(n);
  vec2 offset = vec2(rngNext(rng), rngNext(rng)); // systematic: ONE random pair per hit
  // The reflectors' light samples come from a stream of their own, so the obscurance rays are
  // the same with and without them.
  uint reflectorRng = pcgHash(rng ^ 0x2545f491u);
  vec3 origin = offsetRayOrigin(sp.position, sp.ng);
  const vec3 rP = obscuranceReflectance(sp);
  const float invN = 1.0 / float(max(n, 1u));
  float w = 0.0;
  vec3 wGrey = vec3(0.0); // W with kappa on reflectors (grey obscurance)
  vec3 wc = vec3(0.0);
  uint reflectorRays = 0u;
  for (uint i = 0u; i < n; ++i) {
    vec2 u = systematic ? offset : vec2(rngNext(rng), rngNext(rng));
    vec3 local = systematic ? sampleSystematic(i, grid, offset) : sampleCosineHemisphere(u);
    // The tangent frame made again for every ray, not kept across its traversal: six floats fewer
    // live in the traversal loop (each a register per lane on lavapipe).
    vec3 t, b;
    orthonormalBasis(sp.ns, t, b);
    vec3 direction = toWorld(local, t, b, sp.ns);
    float r = 0.0; // a direction into the surface is blocked at d = 0 (rho(0) = 0)
    vec3 reflectance = vec3(0.0);
    vec3 share = vec3(1.0);
    if (dot(direction, sp.ng) > 0.0) {
      RayHit h = traceWithBudget(budget, origin, direction, 0.0, dMax, false);
      if (rayHitValid(h) && h.primitive != kInvalidIndex) {
        r = rho(h.t, dMax, rhoKind, pc.tau);
        bool reflector = reflectors && triangleShadingAt(h.primitive).n2.w != 0.0;
        // An unmarked surface keeps the later bounces and the first scaled by r (the marked
        // ones hold more than the mean direct light, the rest less; secondary_reflectors.h).
        if (reflectors && !reflector && pc.unmarkedFirstBounce != 1.0) share = pc.kappa + pc.unmarkedFirstBounce * (1.0 - pc.kappa);
        if (bleed || reflector) {
          Surface s = surfaceAt(h, origin, direction);
          reflectance = bleed ? reflectanceAt(s) : vec3(0.0);
          if (reflector) {
            share = pc.kappa;
            vec3 contribution;
            uint light;
            uint tracedBefore = budget.traced;
            vec4 uLight = rngNext4(reflectorRng);
            reflectedDirectLight(s, direction, uLight, budget, contribution, light);
            if (budget.traced != tracedBefore) ++reflectorRays;
            if (light != kInvalidIndex && any(greaterThan(contribution, vec3(0.0))))
              OBS_ACCUMULATE_TEXEL(basis, light * pixelCount + reflectorPixel, vec4(rP * contribution * invN, 0.0))
          }
        }
      } else {
        r = 1.0;
        reflectance = pc.averageReflectance;
        // Traced on past dMax where rays can leave the scene (kFlagDarkEscapes): one that leaves
        // it sees the background, which is a light of its own (its direct light is sampled), not
        // the ambient light between surfaces; a truncated one keeps the ambient.
        if (darkEscapes) {
          ++farRays;
          RayHit far = traceWithBudget(budget, origin, direction, dMax, 1.0 / 0.0, true);
          if (far.primitive == kInvalidIndex) share = vec3(0.0);
        }
      }
    }
    w += r; // W keeps the paper's meaning (openness within dMax): an escape is open
    wGrey += share * r;
    wc += share * reflectance * r;
  }
  if (reflectorRays > 0u) atomicAdd(status[kStatusShadowRays], reflectorRays);
  w *= invN;
  wGrey *= invN;
  wc *= invN;
  return vec4(rP * (bleed ? wc : wGrey), w);
}

#endif
