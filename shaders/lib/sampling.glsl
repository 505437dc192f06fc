// sampling.glsl — warps from [0,1)^2 to directions and points, each with its pdf (and, where one
// exists, its inverse), and the GGX microfacet distribution that bsdf.glsl builds on.
//
// Directions are in a local frame with z = the normal unless a function says otherwise. Depends on
// nothing but GLSL (include shared/host_device.h before it, as every kernel does).
// The C++ twins carry the same names (host/render/bsdf.h, namespace obscura::render) and run the
// same float operations; tests/shaders/sampling_test.* checks the warps (chi-square, round trips,
// one ray per systematic cell) on the GPU and against the twins.
#ifndef OBSCURA_SAMPLING_GLSL
#define OBSCURA_SAMPLING_GLSL

const float kPi = 3.14159265358979323846;
const float kInvPi = 0.31830988618379067154;
// The largest float below 1 (0x3F7FFFFF): warps clamp u to it so a cell index never reaches n.
const float kOneMinusEpsilon = 0.99999994;
// OURS: the smallest GGX alpha. D's peak is 1 / (pi alpha^2): alpha = 1e-3 keeps it (3.2e5), the
// pdfs and f cos / pdf comfortably inside fp32, and the lobe ~1e4 times wider than the angular
// resolution of an fp32 unit vector (~6e-8 rad), so a sampled direction and its density stay
// consistent. Such a lobe looks like a mirror at any image resolution; below kMirrorRoughness
// (bsdf.glsl) the lobe is a true mirror (a delta) instead.
const float kGgxMinAlpha = 1e-3;

// ---- Frames

// An orthonormal basis (t, b, n) around the unit vector n, branch-free but for the sign of n.z.
// Duff, Burgess, Christensen, Hery, Kensler, Liani & Villemin, "Building an Orthonormal Basis,
// Revisited", JCGT 6(1), 2017 (their listing 3).
void orthonormalBasis(vec3 n, out vec3 t, out vec3 b) {
  float s = n.z >= 0.0 ? 1.0 : -1.0; // not sign(): it is 0 at n.z = 0
  float a = -1.0 / (s + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Local (z = n) to world.
vec3 toWorld(vec3 local, vec3 t, vec3 b, vec3 n) {
  return local.x * t + local.y * b + local.z * n;
}

// ---- Cosine-weighted hemisphere (Malley's method, polar form): a uniform point on the unit disk,
// r = sqrt(u.y), projected up. sin^2(theta) = u.y and phi = 2 pi u.x, which is exactly the
// parameterisation of [RTO §4.2]'s systematic sampling, so sampleSystematic reuses it.
// pdf = cos(theta) / pi over solid angle.
vec3 sampleCosineHemisphere(vec2 u) {
  u = min(u, vec2(kOneMinusEpsilon));
  float sinTheta = sqrt(u.y);
  float cosTheta = sqrt(1.0 - u.y);
  float phi = 2.0 * kPi * u.x;
  return vec3(sinTheta * cos(phi), sinTheta * sin(phi), cosTheta);
}

float cosineHemispherePdf(float cosTheta) {
  return max(cosTheta, 0.0) * kInvPi;
}

// The u that sampleCosineHemisphere maps to w (w unit, w.z >= 0). u.x in [0, 1); the pole maps to
// u = (0, 0).
vec2 invertCosineHemisphereSample(vec3 w) {
  float sin2Theta = w.x * w.x + w.y * w.y; // not 1 - z^2: exact near the pole
  float phi = (w.x == 0.0 && w.y == 0.0) ? 0.0 : atan(w.y, w.x);
  float ux = phi * (0.5 * kInvPi);
  if (ux < 0.0) ux += 1.0;
  return vec2(min(ux, kOneMinusEpsilon), min(sin2Theta, 1.0));
}

// ---- Systematic sampling [RTO §4.2, SPEC §1.4]

// (nPhi, nTheta) with nPhi * nTheta == n, as square as possible, nPhi >= nTheta: nTheta is the
// largest divisor of n not above sqrt(n). 40 -> 8x5, 16 -> 4x4, 5 -> 5x1, a prime p -> p x 1.
// n = 0 gives (0, 0).
uvec2 systematicGrid(uint n) {
  if (n == 0u) return uvec2(0u);
  uint d = uint(sqrt(float(n)));
  while (d * d > n) --d;               // exact floor(sqrt(n)) whatever the float rounding
  while ((d + 1u) * (d + 1u) <= n) ++d;
  while (n % d != 0u) --d;             // ends at 1 at the latest
  return uvec2(n / d, d);
}

// Ray i of a hit's systematic set: cell (iPhi, jTheta) = (i % nPhi, i / nPhi) of the
// nPhi x nTheta grid, shifted by the hit's ONE random pair `offset` in [0,1)^2, scaled inside to
// x1 in [0, 1/nPhi), x2 in [0, 1/nTheta):
//     phi = 2 pi (x1 + iPhi / nPhi),    theta = asin(sqrt(x2 + jTheta / nTheta))    [RTO §4.2]
// Over i < nPhi * nTheta every cell gets exactly one ray; over random offsets each ray is
// cosine-distributed within its cell, so the set is cosine-distributed (pdf cos(theta) / pi).
vec3 sampleSystematic(uint i, uvec2 grid, vec2 offset) {
  vec2 cell = vec2(float(i % grid.x), float(i / grid.x));
  return sampleCosineHemisphere((cell + offset) / vec2(grid));
}

// ---- Triangles

float triangleArea(vec3 v0, vec3 v1, vec3 v2) {
  return 0.5 * length(cross(v1 - v0, v2 - v0));
}

// A point uniform by area (pdf = 1 / triangleArea): barycentrics (1 - sqrt(u.x),
// sqrt(u.x) (1 - u.y), sqrt(u.x) u.y). Osada, Funkhouser, Chazelle & Dobkin, "Shape
// Distributions", ACM TOG 21(4), 2002, eq. 1.
vec3 sampleUniformTriangle(vec2 u, vec3 v0, vec3 v1, vec3 v2) {
  float r = sqrt(u.x);
  return (1.0 - r) * v0 + (r * (1.0 - u.y)) * v1 + (r * u.y) * v2;
}

// ---- Spherical triangles: directions uniform over the solid angle a triangle subtends.
// a, b, c: unit vectors from the shading point to the vertices.

// Solid angle of the spherical triangle (a, b, c): Van Oosterom & Strackee, "The Solid Angle of a
// Plane Triangle", IEEE Trans. Biomed. Eng. 30(2), 1983:
//   tan(Omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a)
// Accurate for small triangles, where the angle-sum formula (alpha + beta + gamma - pi) cancels.
float sphericalTriangleArea(vec3 a, vec3 b, vec3 c) {
  return 2.0 * atan(abs(dot(a, cross(b, c))), 1.0 + dot(a, b) + dot(b, c) + dot(c, a));
}

// Component of v orthogonal to unit w, normalised.
vec3 orthogonalUnit(vec3 v, vec3 w) { return normalize(v - dot(v, w) * w); }

// A direction uniform over the spherical triangle (a, b, c) (pdf = 1 / its area): Arvo, "Stratified
// Sampling of Spherical Triangles", SIGGRAPH 1995, §3. u.x picks the sub-triangle (a, b, c') of
// area u.x * area, which fixes c' on the arc ac; u.y picks the point on the arc from b to c' so
// that the area swept grows linearly. Callers keep it to triangles whose area is in
// [kMinSphericalSampleArea, kMaxSphericalSampleArea] (lights.glsl); outside, area sampling.
vec3 sampleSphericalTriangle(vec2 u, vec3 a, vec3 b, vec3 c) {
  // The interior angle at a, between the great circles ab and ac, as atan2(|sin|, cos) (acos loses
  // precision near 0 and pi); the area from Van Oosterom & Strackee rather than the angle sum
  // alpha + beta + gamma - pi, which cancels for small triangles. The same area is the pdf's.
  vec3 nab = normalize(cross(a, b)), nac = normalize(cross(a, c));
  float alpha = atan(length(cross(nab, nac)), dot(nab, nac));
  float area = sphericalTriangleArea(a, b, c);
  float areaPrime = u.x * area;
  float s = sin(areaPrime - alpha), t = cos(areaPrime - alpha);
  float sinAlpha = sin(alpha), cosAlpha = cos(alpha);
  float uu = t - cosAlpha;
  float vv = s + sinAlpha * dot(a, b); // cos(c) = a.b: the arc opposite vertex c
  float denominator = (vv * s + uu * t) * sinAlpha;
  float q = denominator != 0.0 ? clamp(((vv * t - uu * s) * cosAlpha - vv) / denominator, -1.0, 1.0) : 1.0;
  vec3 cPrime = q * a + sqrt(max(0.0, 1.0 - q * q)) * orthogonalUnit(c, a);
  float z = 1.0 - u.y * (1.0 - dot(cPrime, b));
  z = clamp(z, -1.0, 1.0);
  return normalize(z * b + sqrt(max(0.0, 1.0 - z * z)) * orthogonalUnit(cPrime, b));
}

// ---- GGX (Trowbridge-Reitz) microfacets, isotropic, local frame (z = macro normal).
// Walter, Marschner, Li & Torrance, "Microfacet Models for Refraction through Rough Surfaces",
// EGSR 2007 (D); Heitz, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
// JCGT 3(2), 2014 (Smith G1 and the height-correlated G2).

// alpha from glTF's perceptual roughness: alpha = roughness^2, at least kGgxMinAlpha.
float ggxAlpha(float roughness) {
  return max(roughness * roughness, kGgxMinAlpha);
}

// D(h) = alpha^2 / (pi (alpha^2 cos^2 + sin^2)^2), written with sin^2 = (1 - c)(1 + c).
// Narrow lobes: a cosine rounded to fp32 next to 1 moves D by ~1e-7 / alpha^2 relative per ulp;
// where the half vector itself is at hand, use the vector form below.
float ggxD(float cosThetaH, float alpha) {
  if (cosThetaH <= 0.0) return 0.0;
  float a2 = alpha * alpha;
  float sin2 = (1.0 - cosThetaH) * (1.0 + cosThetaH);
  float d = a2 * cosThetaH * cosThetaH + sin2;
  return a2 / (kPi * d * d);
}

// The same D for a half vector h of any length (e.g. wo + wi unnormalised), with sin^2 and cos^2
// taken from its components: alpha^2 |h|^4 / (pi (alpha^2 h.z^2 + h.x^2 + h.y^2)^2). Accurate
// for every alpha >= kGgxMinAlpha, where the cosine form is not.
float ggxD(vec3 h, float alpha) {
  if (h.z <= 0.0) return 0.0;
  float a2 = alpha * alpha;
  float len2 = dot(h, h);
  float d = a2 * h.z * h.z + h.x * h.x + h.y * h.y;
  return a2 * len2 * len2 / (kPi * d * d);
}

// sqrt(cos^2 + alpha^2 sin^2): Smith's Lambda = (ggxLambdaRoot / cos - 1) / 2.
float ggxLambdaRoot(float cosTheta, float alpha) {
  float sin2 = (1.0 - cosTheta) * (1.0 + cosTheta);
  return sqrt(cosTheta * cosTheta + alpha * alpha * sin2);
}

// Masking G1(w) = 1 / (1 + Lambda(w)) = 2 cos / (cos + root); 0 below the horizon.
float smithG1(float cosTheta, float alpha) {
  if (cosTheta <= 0.0) return 0.0;
  return 2.0 * cosTheta / (cosTheta + ggxLambdaRoot(cosTheta, alpha));
}

// Height-correlated masking-shadowing for reflection, G2 = 1 / (1 + Lambda(wo) + Lambda(wi))
// = 2 co ci / (ro ci + ri co), finite for grazing directions.
float smithG2(float cosThetaO, float cosThetaI, float alpha) {
  if (cosThetaO <= 0.0 || cosThetaI <= 0.0) return 0.0;
  float ro = ggxLambdaRoot(cosThetaO, alpha);
  float ri = ggxLambdaRoot(cosThetaI, alpha);
  return 2.0 * cosThetaO * cosThetaI / (ro * cosThetaI + ri * cosThetaO);
}

// A microfacet normal h distributed as the normals visible from wo (wo.z > 0):
// D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z. Heitz, "Sampling the GGX Distribution of Visible
// Normals", JCGT 7(4), 2018: stretch wo to alpha = 1, sample the projected hemisphere as a disk whose
// far half is squeezed by the view, lift the point onto the hemisphere, unstretch.
vec3 sampleGgxVisibleNormal(vec3 wo, float alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lenSq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lenSq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lenSq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0 * kPi * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Density of sampleGgxVisibleNormal over microfacet normals (solid angle of h).
float ggxVisibleNormalPdf(vec3 wo, vec3 h, float alpha) {
  if (wo.z <= 0.0) return 0.0;
  return smithG1(wo.z, alpha) * max(0.0, dot(wo, h)) * ggxD(h, alpha) / wo.z;
}

// Density over wi of wi = reflect(-wo, h) with h from sampleGgxVisibleNormal: the visible-normal
// pdf times the reflection Jacobian 1 / (4 wo.h),
// = G1(wo) D(h) / (4 wo.z).
// Defined for every wi, also below the horizon, where the sampler loses those directions.
float ggxReflectionPdf(vec3 wo, vec3 wi, float alpha) {
  vec3 sum = wo + wi;
  float len2 = dot(sum, sum);
  if (wo.z <= 0.0 || len2 <= 0.0) return 0.0;
  if (dot(wo, sum) <= 0.0) return 0.0;
  return smithG1(wo.z, alpha) * ggxD(sum, alpha) / (4.0 * wo.z);
}

#endif
