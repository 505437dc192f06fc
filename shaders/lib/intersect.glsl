// intersect.glsl — ray/triangle and ray/box tests shared by every pass and by the shader tests.
// The CPU twin is host/bvh/triangle_intersect.cpp; tests/shaders/intersect_test checks both agree.
#ifndef OBSCURA_INTERSECT_GLSL
#define OBSCURA_INTERSECT_GLSL

// Per-ray constants of the watertight test, in matrix form: row i of `shear` maps a vertex
// relative to the origin into the ray's sheared space, so each vertex costs three dot products
// instead of dynamically indexed components (a per-lane gather on lavapipe).
struct WatertightRay {
  vec3 origin;
  vec3 rowX;   // e_kx - Sx e_kz
  vec3 rowY;   // e_ky - Sy e_kz
  vec3 rowZ;   // Sz e_kz
};

vec3 axisVector(int k) { return vec3(k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0); }

// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013, §3:
// kz = the axis of largest |d| (first one on ties), kx/ky the next two, swapped when d[kz] < 0 so
// the winding is kept; shear Sx = d[kx]/d[kz], Sy = d[ky]/d[kz], Sz = 1/d[kz].
WatertightRay prepareWatertightRay(vec3 origin, vec3 direction) {
  vec3 a = abs(direction);
  int kz = 0;
  if (a.y > a[kz]) kz = 1;
  if (a.z > a[kz]) kz = 2;
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  float dz = direction[kz];
  if (dz < 0.0) { int tmp = kx; kx = ky; ky = tmp; }
  WatertightRay r;
  r.origin = origin;
  r.rowX = axisVector(kx) - (direction[kx] / dz) * axisVector(kz);
  r.rowY = axisVector(ky) - (direction[ky] / dz) * axisVector(kz);
  r.rowZ = (1.0 / dz) * axisVector(kz);
  return r;
}

// Returns true when the ray hits the triangle at tmin < t <= tmax (closed at tmax so callers can
// break ties in t by primitive id). u, v are the barycentrics of v1 and v2. No epsilon: the edge
// functions U, V, W are exact in sign for shared edges, so no ray slips between two triangles.
// OURS: no double-precision fallback when U, V or W is exactly 0 (the paper's §3.3); such a ray
// counts as hitting the edge, which is still watertight.
bool intersectTriangle(WatertightRay r, vec3 p0, vec3 p1, vec3 p2, float tmin, float tmax,
                       out float t, out float u, out float v) {
  vec3 A = p0 - r.origin, B = p1 - r.origin, C = p2 - r.origin;
  float Ax = dot(r.rowX, A), Ay = dot(r.rowY, A);
  float Bx = dot(r.rowX, B), By = dot(r.rowY, B);
  float Cx = dot(r.rowX, C), Cy = dot(r.rowY, C);
  // Scaled barycentrics (2D edge functions), paper eq. in §3.2.
  float U = Cx * By - Cy * Bx;
  float V = Ax * Cy - Ay * Cx;
  float W = Bx * Ay - By * Ax;
  t = 0.0; u = 0.0; v = 0.0;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  float det = U + V + W;
  if (det == 0.0) return false;
  float T = U * dot(r.rowZ, A) + V * dot(r.rowZ, B) + W * dot(r.rowZ, C);
  float inv = 1.0 / det;
  t = T * inv;
  u = V * inv;
  v = W * inv;
  return t > tmin && t <= tmax;
}

// Direction reciprocal for slab tests. A zero component becomes a huge finite value of the same
// sign instead of inf, so (bound - origin) * inv is never 0 * inf = NaN.
vec3 safeReciprocal(vec3 d) {
  const float kTiny = 1e-30;
  vec3 m = max(abs(d), vec3(kTiny));
  return vec3(d.x < 0.0 ? -1.0 : 1.0, d.y < 0.0 ? -1.0 : 1.0, d.z < 0.0 ? -1.0 : 1.0) / m;
}

// Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013: scaling the far distance by 1 + 2 gamma(3)
// makes the float slab test conservative, so rounding never culls a box the ray touches.
const float kBoxFarScale = 1.0000004;

// Slab test; returns (tnear, tfar): the box is hit when tnear <= tfar.
vec2 intersectBox(vec3 lo, vec3 hi, vec3 origin, vec3 invDir, float tmin, float tmax) {
  vec3 t0 = (lo - origin) * invDir;
  vec3 t1 = (hi - origin) * invDir;
  vec3 tSmall = min(t0, t1), tBig = max(t0, t1);
  float tNear = max(max(tSmall.x, tSmall.y), max(tSmall.z, tmin));
  float tFar = min(min(tBig.x, tBig.y), min(tBig.z, tmax)) * kBoxFarScale;
  return vec2(tNear, tFar);
}

#endif
