#include "shading/bsdf.h"

#include <algorithm>
#include <cmath>

namespace obscura::shading {

// ---- Sampling (twins of shaders/lib/sampling.glsl; comments and citations there)

void orthonormalBasis(glm::vec3 n, glm::vec3& t, glm::vec3& b) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  t = glm::vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}

glm::vec3 toWorld(glm::vec3 local, glm::vec3 t, glm::vec3 b, glm::vec3 n) {
  return local.x * t + local.y * b + local.z * n;
}

glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
  u = glm::min(u, glm::vec2(kOneMinusEpsilon));
  float sinTheta = std::sqrt(u.y);
  float cosTheta = std::sqrt(1.0f - u.y);
  float phi = 2.0f * kPi * u.x;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

float cosineHemispherePdf(float cosTheta) { return std::max(cosTheta, 0.0f) * kInvPi; }

glm::vec2 invertCosineHemisphereSample(glm::vec3 w) {
  float sin2Theta = w.x * w.x + w.y * w.y;
  float phi = (w.x == 0.0f && w.y == 0.0f) ? 0.0f : std::atan2(w.y, w.x);
  float ux = phi * (0.5f * kInvPi);
  if (ux < 0.0f) ux += 1.0f;
  return {std::min(ux, kOneMinusEpsilon), std::min(sin2Theta, 1.0f)};
}

glm::uvec2 systematicGrid(std::uint32_t n) {
  if (n == 0) return glm::uvec2(0);
  auto d = static_cast<std::uint32_t>(std::sqrt(static_cast<float>(n)));
  while (d * d > n) --d;
  while ((d + 1) * (d + 1) <= n) ++d;
  while (n % d != 0) --d;
  return {n / d, d};
}

glm::vec3 sampleSystematic(std::uint32_t i, glm::uvec2 grid, glm::vec2 offset) {
  glm::vec2 cell(static_cast<float>(i % grid.x), static_cast<float>(i / grid.x));
  return sampleCosineHemisphere((cell + offset) / glm::vec2(grid));
}

float triangleArea(glm::vec3 v0, glm::vec3 v1, glm::vec3 v2) {
  return 0.5f * glm::length(glm::cross(v1 - v0, v2 - v0));
}

float sphericalTriangleArea(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  return 2.0f * std::atan2(std::abs(glm::dot(a, glm::cross(b, c))), 1.0f + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a));
}

glm::vec3 orthogonalUnit(glm::vec3 v, glm::vec3 w) { return glm::normalize(v - glm::dot(v, w) * w); }

glm::vec3 sampleSphericalTriangle(glm::vec2 u, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  glm::vec3 nab = glm::normalize(glm::cross(a, b)), nac = glm::normalize(glm::cross(a, c));
  float alpha = std::atan2(glm::length(glm::cross(nab, nac)), glm::dot(nab, nac));
  float area = sphericalTriangleArea(a, b, c);
  float areaPrime = u.x * area;
  float s = std::sin(areaPrime - alpha), t = std::cos(areaPrime - alpha);
  float sinAlpha = std::sin(alpha), cosAlpha = std::cos(alpha);
  float uu = t - cosAlpha;
  float vv = s + sinAlpha * glm::dot(a, b);
  float denominator = (vv * s + uu * t) * sinAlpha;
  float q = denominator != 0.0f ? std::clamp(((vv * t - uu * s) * cosAlpha - vv) / denominator, -1.0f, 1.0f) : 1.0f;
  glm::vec3 cPrime = q * a + std::sqrt(std::max(0.0f, 1.0f - q * q)) * orthogonalUnit(c, a);
  float z = 1.0f - u.y * (1.0f - glm::dot(cPrime, b));
  z = std::clamp(z, -1.0f, 1.0f);
  return glm::normalize(z * b + std::sqrt(std::max(0.0f, 1.0f - z * z)) * orthogonalUnit(cPrime, b));
}

float ggxAlpha(float roughness) { return std::max(roughness * roughness, kGgxMinAlpha); }

float ggxD(float cosThetaH, float alpha) {
  if (cosThetaH <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float sin2 = (1.0f - cosThetaH) * (1.0f + cosThetaH);
  float d = a2 * cosThetaH * cosThetaH + sin2;
  return a2 / (kPi * d * d);
}

float ggxD(glm::vec3 h, float alpha) {
  if (h.z <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float len2 = glm::dot(h, h);
  float d = a2 * h.z * h.z + h.x * h.x + h.y * h.y;
  return a2 * len2 * len2 / (kPi * d * d);
}

float ggxLambdaRoot(float cosTheta, float alpha) {
  float sin2 = (1.0f - cosTheta) * (1.0f + cosTheta);
  return std::sqrt(cosTheta * cosTheta + alpha * alpha * sin2);
}

float smithG1(float cosTheta, float alpha) {
  if (cosTheta <= 0.0f) return 0.0f;
  return 2.0f * cosTheta / (cosTheta + ggxLambdaRoot(cosTheta, alpha));
}

float smithG2(float cosThetaO, float cosThetaI, float alpha) {
  if (cosThetaO <= 0.0f || cosThetaI <= 0.0f) return 0.0f;
  float ro = ggxLambdaRoot(cosThetaO, alpha);
  float ri = ggxLambdaRoot(cosThetaI, alpha);
  return 2.0f * cosThetaO * cosThetaI / (ro * cosThetaI + ri * cosThetaO);
}

glm::vec3 sampleGgxVisibleNormal(glm::vec3 wo, float alpha, glm::vec2 u) {
  glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lenSq = vh.x * vh.x + vh.y * vh.y;
  glm::vec3 t1 = lenSq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lenSq) : glm::vec3(1.0f, 0.0f, 0.0f);
  glm::vec3 t2 = glm::cross(vh, t1);
  float r = std::sqrt(u.x);
  float phi = 2.0f * kPi * u.y;
  float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)));
}

float ggxVisibleNormalPdf(glm::vec3 wo, glm::vec3 h, float alpha) {
  if (wo.z <= 0.0f) return 0.0f;
  return smithG1(wo.z, alpha) * std::max(0.0f, glm::dot(wo, h)) * ggxD(h, alpha) / wo.z;
}

float ggxReflectionPdf(glm::vec3 wo, glm::vec3 wi, float alpha) {
  glm::vec3 sum = wo + wi;
  float len2 = glm::dot(sum, sum);
  if (wo.z <= 0.0f || len2 <= 0.0f) return 0.0f;
  if (glm::dot(wo, sum) <= 0.0f) return 0.0f;
  return smithG1(wo.z, alpha) * ggxD(sum, alpha) / (4.0f * wo.z);
}

// ---- BSDF (twins of shaders/lib/bsdf.glsl; the model is documented there)

bool isGlossy(float metallic, float roughness) { return !(metallic == 0.0f && roughness == 1.0f); }

bool isMirror(float roughness) { return roughness < kMirrorRoughness; }

glm::vec3 fresnelSchlick(glm::vec3 f0, float cosTheta) {
  float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (glm::vec3(1.0f) - f0) * (m2 * m2 * m);
}

float fresnelSchlick(float f0, float cosTheta) {
  float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (1.0f - f0) * (m2 * m2 * m);
}

float averageRgb(glm::vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

float specularProbability(glm::vec3 baseColor, float metallic, float cosThetaO) {
  glm::vec3 f0 = glm::mix(glm::vec3(kDielectricF0), baseColor, metallic);
  float spec = averageRgb(fresnelSchlick(f0, cosThetaO));
  float diffuse = (1.0f - metallic) * averageRgb(baseColor) * (1.0f - fresnelSchlick(kDielectricF0, cosThetaO));
  float total = spec + diffuse;
  return total > 0.0f ? spec / total : 1.0f;
}

glm::vec3 evalSpecularLobe(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f || !isGlossy(metallic, roughness) || isMirror(roughness)) return glm::vec3(0.0f);
  float alpha = ggxAlpha(roughness);
  glm::vec3 f0 = glm::mix(glm::vec3(kDielectricF0), baseColor, metallic);
  glm::vec3 h = glm::normalize(wo + wi);
  float dg = ggxD(wo + wi, alpha) * smithG2(wo.z, wi.z, alpha) / (4.0f * wo.z * wi.z);
  return fresnelSchlick(f0, std::max(glm::dot(wo, h), 0.0f)) * dg;
}

glm::vec3 evalBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  if (!isGlossy(metallic, roughness)) return baseColor * kInvPi;
  float transmit = (1.0f - fresnelSchlick(kDielectricF0, wo.z)) * (1.0f - fresnelSchlick(kDielectricF0, wi.z));
  glm::vec3 f = ((1.0f - metallic) * transmit * kInvPi / (1.0f - kDielectricFresnelMean)) * baseColor;
  return f + evalSpecularLobe(baseColor, metallic, roughness, wo, wi);
}


float bsdfPdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  if (!isGlossy(metallic, roughness)) return cosineHemispherePdf(wi.z);
  float pSpec = specularProbability(baseColor, metallic, wo.z);
  float pdf = (1.0f - pSpec) * cosineHemispherePdf(wi.z);
  if (!isMirror(roughness)) pdf += pSpec * ggxReflectionPdf(wo, wi, ggxAlpha(roughness));
  return pdf;
}

glm::vec3 sampleBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 u3,
                     glm::vec3& wi, float& pdf, bool& delta) {
  wi = glm::vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  delta = false;
  if (wo.z <= 0.0f) return glm::vec3(0.0f);
  if (!isGlossy(metallic, roughness)) {
    wi = sampleCosineHemisphere(glm::vec2(u3.y, u3.z));
    pdf = cosineHemispherePdf(wi.z);
    return baseColor;
  }
  float pSpec = specularProbability(baseColor, metallic, wo.z);
  bool mirror = isMirror(roughness);
  if (u3.x < pSpec) {
    if (mirror) {
      wi = glm::vec3(-wo.x, -wo.y, wo.z);
      pdf = pSpec;
      delta = true;
      return fresnelSchlick(glm::mix(glm::vec3(kDielectricF0), baseColor, metallic), wo.z) / pSpec;
    }
    glm::vec3 h = sampleGgxVisibleNormal(wo, ggxAlpha(roughness), glm::vec2(u3.y, u3.z));
    wi = glm::reflect(-wo, h);
    if (wi.z <= 0.0f) return glm::vec3(0.0f);
  } else {
    wi = sampleCosineHemisphere(glm::vec2(u3.y, u3.z));
  }
  pdf = bsdfPdf(baseColor, metallic, roughness, wo, wi);
  if (pdf <= 0.0f) return glm::vec3(0.0f);
  return evalBsdf(baseColor, metallic, roughness, wo, wi) * (wi.z / pdf);
}

glm::vec3 sampleBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 u3,
                     glm::vec3& wi, float& pdf) {
  bool delta = false;
  return sampleBsdf(baseColor, metallic, roughness, wo, u3, wi, pdf, delta);
}

// ---- Albedos

glm::vec3 directionalAlbedo(glm::vec3 baseColor, float metallic, float roughness, float cosThetaO, int n) {
  if (!isGlossy(metallic, roughness)) return baseColor;
  cosThetaO = std::clamp(cosThetaO, 0.0f, 1.0f);
  if (cosThetaO <= 0.0f) return glm::vec3(0.0f);
  const glm::vec3 f0 = glm::mix(glm::vec3(kDielectricF0), baseColor, metallic);
  // Diffuse, in closed form: (1 - metallic) baseColor (1 - F_d(cos_o)) (bsdf.glsl).
  glm::dvec3 a = glm::dvec3(baseColor) * ((1.0 - metallic) * (1.0 - fresnelSchlick(kDielectricF0, cosThetaO)));
  if (isMirror(roughness)) return glm::vec3(a + glm::dvec3(fresnelSchlick(f0, cosThetaO)));
  // Specular: importance-sampled by visible normals, f cos / pdf_wi = F(wo.h) G2 / G1(wo)
  // (Heitz 2018), 0 where the reflection leaves the hemisphere. That cut lies in a thin band next
  // to the rim of the sampler's disk (u.x -> 1), so midpoints in t with u.x = 1 - (1 - t)^3
  // (weight 3 (1 - t)^2) crowd there. wo lies in the xz plane, so the integrand is even in the disk
  // coordinate along y (p1 in sampleGgxVisibleNormal): u.y, the disk angle / 2 pi, takes n
  // midpoints in [1/4, 3/4), the half with p1 <= 0, which stands for both halves.
  const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - cosThetaO * cosThetaO)), 0.0f, cosThetaO);
  const float alpha = ggxAlpha(roughness);
  const float g1 = smithG1(wo.z, alpha);
  glm::dvec3 specular(0.0);
  for (int j = 0; j < n; ++j) {
    double t = (j + 0.5) / n;
    double weight = 3.0 * (1.0 - t) * (1.0 - t);
    float ux = static_cast<float>(1.0 - (1.0 - t) * (1.0 - t) * (1.0 - t));
    glm::dvec3 ring(0.0);
    for (int i = 0; i < n; ++i) {
      glm::vec2 u(ux, static_cast<float>(0.25 + 0.5 * (i + 0.5) / n));
      glm::vec3 h = sampleGgxVisibleNormal(wo, alpha, u);
      glm::vec3 wi = glm::reflect(-wo, h);
      if (wi.z <= 0.0f) continue;
      float g = smithG2(wo.z, wi.z, alpha) / g1;
      ring += glm::dvec3(fresnelSchlick(f0, std::max(glm::dot(wo, h), 0.0f)) * g);
    }
    specular += weight * ring;
  }
  return glm::vec3(a + specular / (static_cast<double>(n) * n));
}

glm::vec3 meanAlbedo(glm::vec3 baseColor, float metallic, float roughness, int nOut, int n) {
  if (!isGlossy(metallic, roughness)) return baseColor; // exactly the base colour [SPEC §5]
  // ā = 1/pi ∫ a(wo) cos(theta_o) dwo = ∫_0^1 a(mu) 2 mu dmu, mu = cos(theta_o): midpoints in mu
  // (not in mu^2, which leaves the fast fall of a(mu) at grazing angles to too few nodes).
  glm::dvec3 sum(0.0);
  for (int k = 0; k < nOut; ++k) {
    double mu = (k + 0.5) / nOut;
    sum += 2.0 * mu * glm::dvec3(directionalAlbedo(baseColor, metallic, roughness, static_cast<float>(mu), n));
  }
  return glm::vec3(sum / static_cast<double>(nOut));
}

} // namespace obscura::shading
