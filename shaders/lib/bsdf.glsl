// bsdf.glsl — the material model of [SPEC §5]: evaluate, sample and give the pdf of the BRDF.
//
// * metallic == 0 and roughness == 1: pure Lambertian, f = baseColor / pi (the paper's diffuse
//   surfaces; no specular lobe). isGlossy() is false.
// * anything else is glossy:
//       f = (1 - metallic) baseColor / pi (1 - F_d(cos_o)) (1 - F_d(cos_i)) / (1 - Fbar_d)   diffuse
//         + F(wo.h) D(h) G2(wo, wi) / (4 cos_o cos_i)                               GGX specular
//   F is Schlick's Fresnel with F0 = mix(0.04, baseColor, metallic) (glTF 2.0's metallic-roughness
//   model, Appendix B); F_d the same with F0 = 0.04, the dielectric's own reflectance; Fbar_d its
//   cosine-weighted hemispherical mean. Metals have no diffuse part.
//   OURS: the diffuse lobe is a Lambertian under a Fresnel interface, weighted by the transmittance
//   in and out and normalised by 1 - Fbar_d. That is the coupled diffuse term of Shirley, Hu,
//   Smits & Lafortune, "A Practitioners' Assessment of Light Reflection Models", PG 1997:
//   (21 / 20 pi) (1 - F0) baseColor (1 - (1 - cos_i)^5) (1 - (1 - cos_o)^5). It is reciprocal and
//   its directional albedo is (1 - metallic) baseColor (1 - F_d(cos_o)), so with the specular
//   albedo <= F a white dielectric keeps a(wo) <= 1, R_ave < 1 and I_a = R_ave / (1 - R_ave)
//   [RTO eq. 4] finite. (glTF's (1 - F(wo.h)) weight does not: a white dielectric would reflect
//   1.04 at roughness 0.05, and the plain sum of the brief ~1.08.)
//   alpha = max(roughness^2, kGgxMinAlpha) (sampling.glsl). Below kMirrorRoughness the specular
//   lobe is a perfect mirror: a Dirac delta that evalBsdf and bsdfPdf leave out and only
//   sampleBsdf produces (flagged by `delta`).
//
// Frame and sides: every direction is in the local shading frame, z = shading normal, both pointing
// AWAY from the surface. Reflection is two-sided [SPEC §5]: the caller flips the frame (or wo) so
// that wo.z > 0; for wo.z <= 0 or wi.z <= 0 everything returns 0 (no transmission).
//
// C++ twins with the same names: host/render/bsdf.h (obscura::render); tests/shaders/bsdf_test.*.
#ifndef OBSCURA_BSDF_GLSL
#define OBSCURA_BSDF_GLSL

#include "sampling.glsl"

// OURS: roughness below which the specular lobe is a perfect mirror (alpha = roughness^2 < 1e-4,
// under kGgxMinAlpha anyway). Twin: render::kMirrorRoughness.
const float kMirrorRoughness = 0.01;
// Normal-incidence reflectance of glTF's dielectric (IOR 1.5): ((1.5 - 1) / (1.5 + 1))^2.
const float kDielectricF0 = 0.04;
// The cosine-weighted hemispherical mean of Schlick's Fresnel for F0 = 0.04:
// F0 + (1 - F0) 2 int_0^1 (1 - mu)^5 mu dmu = F0 + (1 - F0) / 21.
const float kDielectricFresnelMean = kDielectricF0 + (1.0 - kDielectricF0) / 21.0;

// [SPEC §5]: only metallic 0 with roughness 1 exactly is Lambertian.
bool isGlossy(float metallic, float roughness) {
  return !(metallic == 0.0 && roughness == 1.0);
}

bool isMirror(float roughness) {
  return roughness < kMirrorRoughness;
}

// Schlick, "An Inexpensive BRDF Model for Physically-based Rendering", CGF 13(3), 1994.
vec3 fresnelSchlick(vec3 f0, float cosTheta) {
  float m = clamp(1.0 - cosTheta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (vec3(1.0) - f0) * (m2 * m2 * m);
}

float fresnelSchlick(float f0, float cosTheta) {
  float m = clamp(1.0 - cosTheta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (1.0 - f0) * (m2 * m2 * m);
}

float averageRgb(vec3 c) {
  return (c.x + c.y + c.z) * (1.0 / 3.0);
}

// OURS: the probability that sampleBsdf picks the specular lobe (glossy materials), its share of
// the reflectance estimated at normal-to-wo facets: spec = avg F(cos_o) with the material's F0,
// diffuse = (1 - metallic) avg(baseColor) (1 - F_d(cos_o)), the two lobes' albedos when the
// specular lobe loses nothing. 1 for metals, ~0.05 for a bright
// dielectric seen head-on, rising towards grazing angles where Fresnel dominates.
float specularProbability(vec3 baseColor, float metallic, float cosThetaO) {
  vec3 f0 = mix(vec3(kDielectricF0), baseColor, metallic);
  float spec = averageRgb(fresnelSchlick(f0, cosThetaO));
  float diffuse = (1.0 - metallic) * averageRgb(baseColor) * (1.0 - fresnelSchlick(kDielectricF0, cosThetaO));
  float total = spec + diffuse;
  return total > 0.0 ? spec / total : 1.0;
}

// The specular (GGX) lobe of evalBsdf alone: 0 for a diffuse material and for a mirror (delta).
// MIS weighs this part of a light sample against the specular pass's lobe sample.
vec3 evalSpecularLobe(vec3 baseColor, float metallic, float roughness, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0 || !isGlossy(metallic, roughness) || isMirror(roughness)) return vec3(0.0);
  float alpha = ggxAlpha(roughness);
  vec3 f0 = mix(vec3(kDielectricF0), baseColor, metallic);
  vec3 h = normalize(wo + wi);
  float dg = ggxD(wo + wi, alpha) * smithG2(wo.z, wi.z, alpha) / (4.0 * wo.z * wi.z);
  return fresnelSchlick(f0, max(dot(wo, h), 0.0)) * dg;
}

// The BRDF f(wo, wi) WITHOUT the cosine (multiply by wi.z yourself). The mirror's delta is left out.
vec3 evalBsdf(vec3 baseColor, float metallic, float roughness, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
  if (!isGlossy(metallic, roughness)) return baseColor * kInvPi;
  float transmit = (1.0 - fresnelSchlick(kDielectricF0, wo.z)) * (1.0 - fresnelSchlick(kDielectricF0, wi.z));
  vec3 f = ((1.0 - metallic) * transmit * kInvPi / (1.0 - kDielectricFresnelMean)) * baseColor;
  return f + evalSpecularLobe(baseColor, metallic, roughness, wo, wi);
}


// The density over solid angle of sampleBsdf's continuous directions (for MIS): the lobes' pdfs
// mixed by specularProbability. A mirror's delta is left out (its mass is specularProbability).
float bsdfPdf(vec3 baseColor, float metallic, float roughness, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  if (!isGlossy(metallic, roughness)) return cosineHemispherePdf(wi.z);
  float pSpec = specularProbability(baseColor, metallic, wo.z);
  float pdf = (1.0 - pSpec) * cosineHemispherePdf(wi.z);
  if (!isMirror(roughness)) pdf += pSpec * ggxReflectionPdf(wo, wi, ggxAlpha(roughness));
  return pdf;
}

// Samples wi for wo (wo.z > 0) with u3 in [0,1)^3: u3.x picks the lobe (specular with
// specularProbability), u3.yz the direction in it: the cosine hemisphere for the diffuse lobe, a GGX
// visible normal for the specular one (Heitz 2018). Returns the weight f(wo, wi) wi.z / pdf.
//   pdf   = bsdfPdf(wo, wi) for a continuous sample; for a mirror reflection (delta = true) the
//           probability of having chosen it, and the weight is F(wo.z) / that probability.
//   pdf = 0 (weight 0): no sample — wo below the horizon, or a specular direction that fell below
//           the horizon (the energy single-scattering GGX loses); end the path there.
vec3 sampleBsdf(vec3 baseColor, float metallic, float roughness, vec3 wo, vec3 u3, out vec3 wi,
                out float pdf, out bool delta) {
  wi = vec3(0.0, 0.0, 1.0);
  pdf = 0.0;
  delta = false;
  if (wo.z <= 0.0) return vec3(0.0);
  if (!isGlossy(metallic, roughness)) {
    wi = sampleCosineHemisphere(u3.yz);
    pdf = cosineHemispherePdf(wi.z);
    return baseColor; // (baseColor / pi) cos / (cos / pi)
  }
  float pSpec = specularProbability(baseColor, metallic, wo.z);
  bool mirror = isMirror(roughness);
  if (u3.x < pSpec) {
    if (mirror) {
      wi = vec3(-wo.x, -wo.y, wo.z);
      pdf = pSpec;
      delta = true;
      return fresnelSchlick(mix(vec3(kDielectricF0), baseColor, metallic), wo.z) / pSpec;
    }
    vec3 h = sampleGgxVisibleNormal(wo, ggxAlpha(roughness), u3.yz);
    wi = reflect(-wo, h);
    if (wi.z <= 0.0) return vec3(0.0);
  } else {
    wi = sampleCosineHemisphere(u3.yz);
  }
  pdf = bsdfPdf(baseColor, metallic, roughness, wo, wi);
  if (pdf <= 0.0) return vec3(0.0);
  return evalBsdf(baseColor, metallic, roughness, wo, wi) * (wi.z / pdf);
}

// The same without the delta flag, for callers that know their material is no mirror.
vec3 sampleBsdf(vec3 baseColor, float metallic, float roughness, vec3 wo, vec3 u3, out vec3 wi,
                out float pdf) {
  bool delta;
  return sampleBsdf(baseColor, metallic, roughness, wo, u3, wi, pdf, delta);
}

#endif
