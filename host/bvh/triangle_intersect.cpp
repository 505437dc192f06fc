// triangle_intersect.cpp — watertight ray/triangle intersection on the CPU.
//
// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013 (cited as [WBW]).
// The GLSL twin (shaders/lib/intersect.glsl) follows these steps one for one, so this stays a
// straight-line, float-only function: no double-precision fallback, no absolute epsilon.
//
// Why the paper needs a fallback at all, and what replaces it here: an edge function
// a*b - c*d computed in float always has the right sign or is 0, because rounding is monotonic
// (a*b > c*d implies fl(a*b) >= fl(c*d)). It is 0 when the two products round to the same float,
// which happens easily for a small triangle far from the ray (measured: a 1e-5 triangle 8 units
// from the ray got U = V = 0 and reported a "hit at its vertex"). The paper recomputes such
// zeros in double. We recompute them in float with two FMAs instead (edgeFunction() below):
// the rounding error of a float product is exactly representable and fma() yields it exactly, so
// (a*b - p) - (c*d - p) has the exact sign of a*b - c*d. That keeps the GPU free of float64 and
// gives the same answers as the double fallback except under underflow (products below ~1e-38),
// where a zero edge function is kept (a possible hit on the edge, never a hole).
//
// Floating-point contraction: the watertightness argument of [WBW] rests on an edge function
// of a shared edge being computed as the exact negation in the neighbouring triangle
// (a*b - c*d versus c*d - a*b). A fused multiply-add breaks that symmetry, so this file must be
// compiled without FP contraction (GCC only contracts when FMA instructions are enabled, e.g. by
// -march=native; the pragmas below switch it off wherever the compiler honours them). The GLSL
// twin needs the same care: declare the edge functions `precise`.
#include "bvh/triangle_intersect.h"

#include <algorithm>
#include <cmath>
#include <utility>

#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

namespace obscura::bvh {
namespace {

// a*b - c*d, with the exact sign: the plain float difference when it is non-zero (its sign is
// then right, see the top of the file), otherwise the difference of the products' exact rounding
// errors (both taken against the same p == q). Exactly antisymmetric: edgeFunction(c, d, a, b)
// == -edgeFunction(a, b, c, d), bit for bit, which is what a shared edge needs.
inline float edgeFunction(float a, float b, float c, float d) {
  const float p = a * b;
  const float q = c * d;
  const float e = p - q;
  return e != 0.0f ? e : std::fma(a, b, -p) - std::fma(c, d, -q);
}

// gamma(n) = n eps / (1 - n eps), eps = 2^-24: the bound on n float roundings [PBR3 §3.9.1].
inline float gammaBound(float n) {
  constexpr float kEpsilon = 0x1p-24f;
  return n * kEpsilon / (1.0f - n * kEpsilon);
}

} // namespace

// Bound on the absolute error of t = T / det, after Pharr, Jakob & Humphreys, "Physically Based
// Rendering" 3rd ed. (PBR3), §3.9.5, with one tightening (OURS): PBR3 multiplies the error of
// the edge functions by max|z|; but t = sum e_i z_i / sum e_i is a weighted mean of the z_i, and
// writing z_i = z0 + d_i shows that errors De_i in the weights move t by at most
// 2 sum|De_i| max|d_i| / |det|, i.e. by the SPREAD of the z_i, not their size. Without this a
// 1e-6 triangle seen from distance 1 (spread 1e-6, |z| = 1) got a bound above t and was lost,
// while a 2000-unit floor under a ray's origin (spread ~1e3) still gets the bound it needs.
// The GLSL twin computes the same expression in the same order.
float triangleTError(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy, float cz,
                     float e0, float e1, float e2, float det, float zScale) {
  const float maxZ = std::max(std::max(std::abs(az), std::abs(bz)), std::abs(cz));
  const float spreadZ = std::max(std::max(az, bz), cz) - std::min(std::min(az, bz), cz);
  const float deltaZ = gammaBound(3.0f) * maxZ;
  const float maxX = std::max(std::max(std::abs(ax), std::abs(bx)), std::abs(cx));
  const float maxY = std::max(std::max(std::abs(ay), std::abs(by)), std::abs(cy));
  // x' = x - Sx z uses the UNSCALED z (|Sx|, |Sy| <= 1): PBR3 adds the scaled max|z| here, which
  // assumes |d| ~ 1 and inflates the bound by 1/|d| for short directions (OURS: fixed).
  const float maxZUnscaled = maxZ / zScale;
  const float deltaX = gammaBound(5.0f) * (maxX + maxZUnscaled);
  const float deltaY = gammaBound(5.0f) * (maxY + maxZUnscaled);
  const float deltaE = 2.0f * ((gammaBound(2.0f) * maxX * maxY + deltaY * maxX) + deltaX * maxY);
  const float maxE = std::max(std::max(std::abs(e0), std::abs(e1)), std::abs(e2));
  // When every vertex lies in front of the origin (beyond its own rounding error), t is a convex
  // combination of positive z_i for any same-signed weights: it cannot be <= 0, so no bound is
  // needed. This keeps grazing hits on slivers far from the origin, where the bound exceeds t.
  const float minZ = std::min(std::min(az, bz), cz);
  if (minZ > deltaZ) return 0.0f;
  return (3.0f * (gammaBound(3.0f) * maxE * maxZ + deltaZ * maxE) + 6.0f * deltaE * spreadZ) * std::abs(1.0f / det);
}

// [WBW], per-ray precomputation: the axis of largest |d| becomes z (so Sz is finite and as
// large as it can be), kx/ky are the next two axes cyclically, swapped when d[kz] < 0 so that the
// permutation keeps the triangle's winding (the signs of U, V, W below).
WatertightRay prepareWatertightRay(const glm::vec3& origin, const glm::vec3& direction) {
  const glm::vec3 a = glm::abs(direction);
  // Ties go to the lowest axis; any fixed rule works as long as the GLSL twin uses the same one.
  int kz = 0;
  if (a.y > a[kz]) kz = 1;
  if (a.z > a[kz]) kz = 2;
  int kx = kz + 1 == 3 ? 0 : kz + 1;
  int ky = kx + 1 == 3 ? 0 : kx + 1;
  if (direction[kz] < 0.0f) std::swap(kx, ky);

  WatertightRay r;
  r.origin = origin;
  r.kx = kx;
  r.ky = ky;
  r.kz = kz;
  // Shear that maps the direction onto +z (scaled so that it has unit z): [WBW].
  r.sx = direction[kx] / direction[kz];
  r.sy = direction[ky] / direction[kz];
  r.sz = 1.0f / direction[kz];
  return r;
}

// [WBW], the algorithm as listed in the paper, float only (see the top of the file).
bool intersectTriangle(const WatertightRay& ray, const glm::vec3& v0, const glm::vec3& v1,
                       const glm::vec3& v2, float tmin, float tmax, float& t, float& u, float& v) {
  // 1. Vertices relative to the ray origin.
  const glm::vec3 a = v0 - ray.origin;
  const glm::vec3 b = v1 - ray.origin;
  const glm::vec3 c = v2 - ray.origin;

  // 2. Shear and scale (x, y only; z is sheared lazily in step 5): in this space the ray is the
  //    +z axis through (0, 0).
  const float ax = a[ray.kx] - ray.sx * a[ray.kz];
  const float ay = a[ray.ky] - ray.sy * a[ray.kz];
  const float bx = b[ray.kx] - ray.sx * b[ray.kz];
  const float by = b[ray.ky] - ray.sy * b[ray.kz];
  const float cx = c[ray.kx] - ray.sx * c[ray.kz];
  const float cy = c[ray.ky] - ray.sy * c[ray.kz];

  // 3. Scaled barycentrics: 2D edge functions of the origin against the opposite edge. U is the
  //    weight of v0 (edge v1-v2), V of v1 (edge v2-v0), W of v2 (edge v0-v1). A shared edge gives
  //    bit-exact negated values in the two triangles, which is what makes the test watertight.
  //    A zero is resolved to its exact sign by edgeFunction() (in place of the paper's double).
  const float uu = edgeFunction(cx, by, cy, bx);
  const float vv = edgeFunction(ax, cy, ay, cx);
  const float ww = edgeFunction(bx, ay, by, ax);

  // 4. Outside when the signs are mixed; zeros count for both sides, so a ray through an edge or
  //    a vertex hits every triangle sharing it (at least one, as promised). Both windings hit.
  if ((uu < 0.0f || vv < 0.0f || ww < 0.0f) && (uu > 0.0f || vv > 0.0f || ww > 0.0f)) return false;

  // 5. Determinant: zero for a ray in the triangle's plane or a degenerate triangle.
  const float det = uu + vv + ww;
  if (det == 0.0f) return false;

  // 6. Scaled hit distance: the z coordinates in sheared space, interpolated with U, V, W.
  const float az = ray.sz * a[ray.kz];
  const float bz = ray.sz * b[ray.kz];
  const float cz = ray.sz * c[ray.kz];
  const float tScaled = uu * az + vv * bz + ww * cz;

  // 7. Normalise. Deviation from [WBW]: the paper tests tScaled against tmin*det and tmax*det
  //    (with det's sign) to save the division on rejected hits. We divide first and test the
  //    quotient, because the two roundings can disagree by an ulp at the boundary: then whether a
  //    triangle is accepted would depend on the tmax it was tested with, i.e. on traversal order,
  //    and "closest hit, ties in t to the lower primitive id" would differ between the BVH, the
  //    brute-force oracle and the GPU. Testing the one rounded t makes acceptance a function of
  //    (ray, triangle) alone. Divisions (not a reciprocal times three) keep t correctly rounded.
  t = tScaled / det;
  u = vv / det; // barycentric of v1
  v = ww / det; // barycentric of v2

  // 8. A t that rounding could have made positive is no hit: the conservative bound on the error
  //    of t from Pharr, Jakob & Humphreys, "Physically Based Rendering" 3rd ed., §3.9.5
  //    ("Ensuring that t is positive"). For a huge triangle the error of t grows with the
  //    vertices' distance from the origin, not with the hit point, so offsetting a secondary
  //    ray's origin (which scales with the hit point) cannot prevent a self-hit alone.
  const float tError = triangleTError(ax, ay, az, bx, by, bz, cx, cy, cz, uu, vv, ww, det, std::abs(ray.sz));

  // 9. Range test, open at tmin, closed at tmax so the caller can pass its best t and break ties
  //    by primitive id. A NaN t (zero direction) compares false and is rejected.
  return t > tmin && t > tError && t <= tmax;
}

} // namespace obscura::bvh
