// shade.glsl — a shading point and its direct light, shared by the shadow pass (primary hits),
// the specular pass (vertices of specular paths) and the path tracer. Needs scene/shading bindings, bvh.glsl,
// ray.glsl, sampling.glsl, bsdf.glsl, lights.glsl, mis.glsl.
#ifndef OBSCURA_SHADE_GLSL
#define OBSCURA_SHADE_GLSL

struct ShadingPoint {
  vec3 position;
  vec3 ng;        // geometric normal, facing wo
  vec3 ns;        // shading normal, same side as ng
  vec3 wo;        // unit direction towards the viewer (or the previous path vertex)
  vec3 baseColor; // base colour x texture
  float metallic;
  float roughness;
  bool glossy;    // has a specular lobe [SPEC §5]
  uint material;
};

ShadingPoint shadingPoint(vec3 position, vec3 ng, vec3 ns, vec3 wo, vec3 baseColor, uint material) {
  ShadingPoint sp;
  sp.position = position;
  sp.ng = ng;
  sp.ns = ns;
  sp.wo = wo;
  sp.baseColor = baseColor;
  sp.material = material;
  GpuMaterial m = materialAt(material);
  sp.metallic = m.params.x;
  sp.roughness = m.params.y;
  sp.glossy = m.params.w != 0.0;
  return sp;
}

ShadingPoint shadingPointFromGBuffer(GBufferTexel g, vec3 eye) {
  return shadingPoint(g.position.xyz, g.geometricNormal.xyz, g.shadingNormal.xyz, normalize(eye - g.position.xyz),
                      g.albedo.rgb, floatBitsToUint(g.shadingNormal.w));
}

// f(wo, wi) of the shading point's BSDF (without the cosine), in world space.
vec3 shadingBsdf(ShadingPoint sp, vec3 wi) {
  if (!sp.glossy) return sp.baseColor * (1.0 / kPi);
  vec3 t, b;
  orthonormalBasis(sp.ns, t, b);
  vec3 woLocal = vec3(dot(sp.wo, t), dot(sp.wo, b), dot(sp.wo, sp.ns));
  vec3 wiLocal = vec3(dot(wi, t), dot(wi, b), dot(wi, sp.ns));
  return evalBsdf(sp.baseColor, sp.metallic, sp.roughness, woLocal, wiLocal);
}

// The reflectance R(P) the obscurance term multiplies [RTO eq. 1]. OURS: at a glossy point
// only the diffuse part, because the specular pass traces the glossy lobe's reflections itself
// (a-bar there would count them twice); a-bar is used for R(Q) and R_ave [SPEC §1.2].
vec3 obscuranceReflectance(ShadingPoint sp) {
  return sp.glossy ? sp.baseColor * (1.0 - sp.metallic) : sp.baseColor;
}

// Local-frame versions of wo and wi at sp (z = shading normal).
void shadingLocal(ShadingPoint sp, vec3 wi, out vec3 woLocal, out vec3 wiLocal) {
  vec3 t, b;
  orthonormalBasis(sp.ns, t, b);
  woLocal = vec3(dot(sp.wo, t), dot(sp.wo, b), dot(sp.wo, sp.ns));
  wiLocal = vec3(dot(wi, t), dot(wi, b), dot(wi, sp.ns));
}

// The density with which specular.comp's lobe sample (GGX visible normals, reflected) picks wi
// at sp; 0 where it cannot: mirrors (a delta), diffuse points, wo or wi below the shading normal.
float specularLobePdf(ShadingPoint sp, vec3 wi) {
  if (!sp.glossy || isMirror(sp.roughness)) return 0.0;
  vec3 woLocal, wiLocal;
  shadingLocal(sp, wi, woLocal, wiLocal);
  if (woLocal.z <= 0.0 || wiLocal.z <= 0.0) return 0.0;
  return ggxReflectionPdf(woLocal, wiLocal, ggxAlpha(sp.roughness));
}

// One shadow ray: contribution (unit emission, before E_s) and the light it belongs to.
// Light arriving below the GEOMETRIC surface is dropped, so interpolated normals never leak light
// through a surface; light above it but below the interpolated shading normal (the terminator of
// a smooth low-poly mesh) uses |cos| with the shading normal, as pbrt does, so no facet turns
// black while its geometry faces the light.
//
// lightSamples > 0: the specular lobe at sp is also sampled once (specular.comp), and this is one
// of lightSamples light samples; the lobe's part of the BSDF gets the power-heuristic weight
// [Veach & Guibas 1995] and the diffuse part stays whole (only light sampling covers it).
void directLightFrom(ShadingPoint sp, LightSample ls, float lightSamples, inout StepBudget budget,
                     out vec3 contribution, out bool visible);

void directLightSample(ShadingPoint sp, vec4 u, uint lightCount, float lightSamples, inout StepBudget budget,
                       out vec3 contribution, out uint light) {
  LightSample ls = sampleLight(sp.position, sp.ng, u, lightCount);
  light = ls.light;
  bool visible;
  directLightFrom(sp, ls, lightSamples, budget, contribution, visible);
}

// Direct light from `light` alone, the relighting paper's visibility sampling [IVR §3.1]:
// kPerLightRays shadow rays to it; where they disagree (a penumbra) more, up to kPerLightMaxRays,
// all averaged. A point, spot or directional light has one shadow ray, whose answer is exact. No
// MIS: the caller counts none of this light's emission found by a lobe sample. `rays` says how
// many were traced.
vec3 directLightFromOne(ShadingPoint sp, uint light, vec4 lightShift, inout StepBudget budget, out uint rays) {
  vec3 sum = vec3(0.0);
  uint seen = 0u;
  rays = 0u;
  const uint type = lightAt(light).info.x;
  const uint first = type == kLightArea || type == kLightBackground ? kPerLightRays : 1u;
  for (uint k = 0u; k < kPerLightMaxRays; ++k) {
    // A probe (lib/probe.glsl) sees every ray reach the light: it tests all the rays a penumbra
    // may have taken.
    if (k == first && (seen == 0u || seen == first) && !kProbe) break;
    vec4 u = kroneckerPoint4(k, lightShift);
    vec3 contribution;
    bool visible;
    directLightFrom(sp, sampleChosenLight(sp.position, sp.ng, u, light, 1.0), 0.0, budget, contribution, visible);
    sum += contribution;
    seen += visible ? 1u : 0u;
    ++rays;
  }
  return sum / float(rays);
}

// The last shadow ray directLightFrom traced from its origin: direction and length (0 when it
// traced none), for the frame to keep (lib/kept_rays.glsl).
vec4 gShadowRay = vec4(0.0);

// The shadow ray of light sample `ls`; `visible` says whether it reached the light (false also
// when the light faces away or lies below the surface: nothing to trace).
void directLightFrom(ShadingPoint sp, LightSample ls, float lightSamples, inout StepBudget budget,
                     out vec3 contribution, out bool visible) {
  contribution = vec3(0.0);
  visible = false;
  gShadowRay = vec4(0.0);
  float cosG = dot(sp.ng, ls.wi);
  float cosS = dot(sp.ns, ls.wi);
  if (cosG <= 0.0 || all(equal(ls.weight, vec3(0.0)))) return;
  cosS = abs(cosS);
  vec3 origin = offsetRayOrigin(sp.position, sp.ng);
  vec3 direction = ls.wi;
  float tmax = 1.0 / 0.0;
  if (!ls.infinite) {
    // Both ends leave their surfaces (Wächter & Binder), so neither the receiver nor the light's
    // own triangle can occlude the segment.
    vec3 target = ls.targetNormal == vec3(0.0) ? ls.target : offsetRayOrigin(ls.target, ls.targetNormal);
    vec3 d = target - origin;
    tmax = length(d);
    direction = d / tmax;
  }
  gShadowRay = vec4(direction, tmax);
  RayHit h = traceWithBudget(budget, origin, direction, 0.0, tmax, true);
  if (kProbe) return; // a probe only tests the ray
  if (h.primitive != kInvalidIndex) return; // occluded (or truncated, reported by the caller)
  visible = true;
  // The BSDF sees the light mirrored above the shading normal when it lies below it.
  vec3 wiShading = dot(sp.ns, ls.wi) < 0.0 ? reflect(ls.wi, sp.ns) : ls.wi;
  vec3 f = shadingBsdf(sp, wiShading);
  if (lightSamples > 0.0 && ls.hittable) { // an area light or the sky: the lobe can reach it too
    float lobePdf = specularLobePdf(sp, ls.wi);
    if (lobePdf > 0.0) {
      vec3 woLocal, wiLocal;
      shadingLocal(sp, ls.wi, woLocal, wiLocal);
      vec3 lobe = evalSpecularLobe(sp.baseColor, sp.metallic, sp.roughness, woLocal, wiLocal);
      f -= (1.0 - powerHeuristic(lightSamples * ls.pdf, lobePdf)) * lobe;
    }
  }
  contribution = f * ls.weight * cosS;
}

#endif
