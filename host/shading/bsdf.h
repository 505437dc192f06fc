// bsdf.h — C++ twins of shaders/lib/sampling.glsl and shaders/lib/bsdf.glsl, plus the mean albedo
// of a material [SPEC §1.2].
//
// Every function below has the same name, arguments and float operations as its GLSL twin, so
// tests can compare the GPU with it and the host can use the same model (light power, R_ave).
// The model, the frame convention (local, z = shading normal, wo and wi pointing away, wo.z > 0:
// callers flip for two-sided reflection) and the citations are documented in the GLSL files;
// tests/shaders/sampling_test.cpp, tests/shaders/bsdf_test.cpp and host/shading/bsdf_test.cpp check
// them.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace obscura::shading {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f; // largest float below 1
// Smallest GGX alpha; why 1e-3: see sampling.glsl.
inline constexpr float kGgxMinAlpha = 1e-3f;
// Roughness below which the specular lobe is a perfect mirror (bsdf.glsl).
inline constexpr float kMirrorRoughness = 0.01f;
// Normal-incidence reflectance of glTF's dielectric (IOR 1.5).
inline constexpr float kDielectricF0 = 0.04f;
// Cosine-weighted hemispherical mean of Schlick's Fresnel for kDielectricF0 (bsdf.glsl).
inline constexpr float kDielectricFresnelMean = kDielectricF0 + (1.0f - kDielectricF0) / 21.0f;

// ---- Sampling (twins of shaders/lib/sampling.glsl)

// Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017.
void orthonormalBasis(glm::vec3 n, glm::vec3& t, glm::vec3& b);
glm::vec3 toWorld(glm::vec3 local, glm::vec3 t, glm::vec3 b, glm::vec3 n);

// Cosine-weighted hemisphere, polar form: phi = 2 pi u.x, sin^2(theta) = u.y; pdf cos(theta) / pi.
glm::vec3 sampleCosineHemisphere(glm::vec2 u);
float cosineHemispherePdf(float cosTheta);
glm::vec2 invertCosineHemisphereSample(glm::vec3 w);

// Systematic sampling [RTO §4.2, SPEC §1.4]: (nPhi, nTheta), nPhi * nTheta == n, nPhi >= nTheta,
// as square as possible; ray i lands in cell (i % nPhi, i / nPhi), shifted by the hit's one offset.
glm::uvec2 systematicGrid(std::uint32_t n);
glm::vec3 sampleSystematic(std::uint32_t i, glm::uvec2 grid, glm::vec2 offset);

// A triangle's area (the pdf of lib/sampling.glsl's area-uniform point is its inverse).
float triangleArea(glm::vec3 v0, glm::vec3 v1, glm::vec3 v2);

// Spherical triangles seen from a point (a, b, c: unit directions to the vertices): the solid
// angle (Van Oosterom & Strackee 1983) and a direction uniform in it (Arvo 1995), pdf 1 / area.
float sphericalTriangleArea(glm::vec3 a, glm::vec3 b, glm::vec3 c);
glm::vec3 orthogonalUnit(glm::vec3 v, glm::vec3 w);
glm::vec3 sampleSphericalTriangle(glm::vec2 u, glm::vec3 a, glm::vec3 b, glm::vec3 c);

// GGX: D (Walter et al. 2007), Smith G1 and height-correlated G2 (Heitz 2014), visible normals
// (Heitz, "Sampling the GGX Distribution of Visible Normals", 2018).
float ggxAlpha(float roughness);
float ggxD(float cosThetaH, float alpha);
float ggxD(glm::vec3 h, float alpha); // h of any length; accurate for narrow lobes
float ggxLambdaRoot(float cosTheta, float alpha);
float smithG1(float cosTheta, float alpha);
float smithG2(float cosThetaO, float cosThetaI, float alpha);
glm::vec3 sampleGgxVisibleNormal(glm::vec3 wo, float alpha, glm::vec2 u);
float ggxVisibleNormalPdf(glm::vec3 wo, glm::vec3 h, float alpha);
float ggxReflectionPdf(glm::vec3 wo, glm::vec3 wi, float alpha);

// ---- BSDF (twins of shaders/lib/bsdf.glsl) [SPEC §5]

bool isGlossy(float metallic, float roughness);
bool isMirror(float roughness);
glm::vec3 fresnelSchlick(glm::vec3 f0, float cosTheta);
float fresnelSchlick(float f0, float cosTheta);
float averageRgb(glm::vec3 c);
float specularProbability(glm::vec3 baseColor, float metallic, float cosThetaO);
// f(wo, wi) without the cosine; the mirror's delta left out.
glm::vec3 evalBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi);
// The specular (GGX) lobe of evalBsdf alone (0 for diffuse materials and mirrors).
glm::vec3 evalSpecularLobe(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi);
// Density of sampleBsdf's continuous directions (the mirror's delta left out).
float bsdfPdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 wi);
// Returns f cos / pdf; pdf = 0: no sample; delta: a mirror reflection, pdf = its probability.
glm::vec3 sampleBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 u3,
                     glm::vec3& wi, float& pdf, bool& delta);
glm::vec3 sampleBsdf(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 wo, glm::vec3 u3,
                     glm::vec3& wi, float& pdf);

// ---- Albedos (host only)

// Directional albedo a(wo) = integral over wi of f cos(theta_i) (the mirror's delta included), for
// wo at cos(theta_o) = cosThetaO: the diffuse part in closed form, the specular part by
// deterministic quadrature over visible normals (n x n midpoints, see bsdf.cpp).
glm::vec3 directionalAlbedo(glm::vec3 baseColor, float metallic, float roughness, float cosThetaO, int n = 32);

// Mean albedo ā = 1/pi ∫∫ f cos(theta_i) cos(theta_o) dwi dwo [RTO eq. 10-13, SPEC §1.2]: the
// cosine-weighted mean of directionalAlbedo over wo (`nOut` midpoints in cos(theta_o)).
// Exactly baseColor for a Lambertian material; accurate to ~5e-4 otherwise, ~2 ms.
glm::vec3 meanAlbedo(glm::vec3 baseColor, float metallic, float roughness, int nOut = 32, int n = 32);

} // namespace obscura::shading
