// intersect.glsl — ray/triangle and ray/box tests shared by every pass and by the shader tests.
// The CPU twin is host/bvh/triangle_intersect.cpp; tests/shaders/intersect_test checks both agree.
#ifndef OBSCURA_INTERSECT_GLSL
#define OBSCURA_INTERSECT_GLSL

// Per-ray constants of the watertight test: the axes kx, ky, kz packed in one word and the shear
// (Sx, Sy, Sz), as the CPU keeps them. Six floats fewer than the shear as three matrix rows: on
// lavapipe every live value of the traversal loop is a register per lane, and spills are a
// quarter of a pass.
struct WatertightRay {
  vec3 origin;
  vec3 shear; // Sx, Sy, Sz
  uint axes;  // kx | ky << 2 | kz << 4
};

// Component k of v by selects (a dynamically indexed component is a per-lane gather on lavapipe).
float axisComponent(vec3 v, uint k) { return k == 0u ? v.x : (k == 1u ? v.y : v.z); }

// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013 ([WBW]):
// kz = the axis of largest |d| (the lowest one on ties, as on the CPU), kx/ky the next two
// cyclically, swapped when d[kz] < 0 so the winding is kept; Sx = d[kx]/d[kz], Sy = d[ky]/d[kz],
// Sz = 1/d[kz].
WatertightRay prepareWatertightRay(vec3 origin, vec3 direction) {
  vec3 a = abs(direction);
  uint kz = 0u;
  if (a.y > axisComponent(a, kz)) kz = 1u;
  if (a.z > axisComponent(a, kz)) kz = 2u;
  uint kx = kz == 2u ? 0u : kz + 1u;
  uint ky = kx == 2u ? 0u : kx + 1u;
  float dz = axisComponent(direction, kz);
  if (dz < 0.0) { uint tmp = kx; kx = ky; ky = tmp; }
  WatertightRay r;
  r.origin = origin;
  r.shear = vec3(axisComponent(direction, kx) / dz, axisComponent(direction, ky) / dz, 1.0 / dz);
  r.axes = kx | (ky << 2) | (kz << 4);
  return r;
}

// The sheared x, y (and scaled z) of a vertex relative to the origin: p[kx] - Sx p[kz],
// p[ky] - Sy p[kz], Sz p[kz], rounded as on the CPU (`precise`: no fused multiply-add).
vec3 shearVertex(WatertightRay r, vec3 p) {
  float pz = axisComponent(p, r.axes >> 4);
  precise float x = axisComponent(p, r.axes & 3u) - r.shear.x * pz;
  precise float y = axisComponent(p, (r.axes >> 2) & 3u) - r.shear.y * pz;
  precise float z = r.shear.z * pz;
  return vec3(x, y, z);
}

// a*b - c*d with its exact sign: when the float difference rounds to 0, the difference of the
// products' exact rounding errors (fma) decides. Exactly antisymmetric, which a shared edge needs.
// Same as edgeFunction() in host/bvh/triangle_intersect.cpp, which explains why it is exact.
float edgeFunction(float a, float b, float c, float d) {
  precise float p = a * b;
  precise float q = c * d;
  precise float e = p - q;
  precise float exact = fma(a, b, -p) - fma(c, d, -q);
  return e != 0.0 ? e : exact;
}

// gamma(n) = n eps / (1 - n eps), eps = 2^-24: the bound on n float roundings [PBR3 §3.9.1].
float gammaBound(float n) {
  const float kEpsilon = 5.9604644775390625e-8; // 2^-24
  return n * kEpsilon / (1.0 - n * kEpsilon);
}

// Bound on the absolute error of t = T / det (Pharr, Jakob & Humphreys, "Physically Based
// Rendering" 3rd ed., §3.9.5, with the edge-function term scaled by the spread of the z_i
// instead of max|z|: see triangleTError() in host/bvh/triangle_intersect.cpp for why). A hit
// with t <= this bound may really lie behind the origin. Same expression, same order as there.
float triangleTError(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy, float cz,
                     float e0, float e1, float e2, float det, float zScale) {
  precise float maxZ = max(max(abs(az), abs(bz)), abs(cz));
  precise float spreadZ = max(max(az, bz), cz) - min(min(az, bz), cz);
  precise float deltaZ = gammaBound(3.0) * maxZ;
  precise float maxX = max(max(abs(ax), abs(bx)), abs(cx));
  precise float maxY = max(max(abs(ay), abs(by)), abs(cy));
  precise float maxZUnscaled = maxZ / zScale; // x' = x - Sx z uses the unscaled z
  precise float deltaX = gammaBound(5.0) * (maxX + maxZUnscaled);
  precise float deltaY = gammaBound(5.0) * (maxY + maxZUnscaled);
  precise float deltaE = 2.0 * ((gammaBound(2.0) * maxX * maxY + deltaY * maxX) + deltaX * maxY);
  precise float maxE = max(max(abs(e0), abs(e1)), abs(e2));
  precise float bound = (3.0 * (gammaBound(3.0) * maxE * maxZ + deltaZ * maxE) + 6.0 * deltaE * spreadZ) * abs(1.0 / det);
  // All vertices in front of the origin: t is a convex combination of positive z_i, never <= 0.
  float minZ = min(min(az, bz), cz);
  return minZ > deltaZ ? 0.0 : bound;
}

// Returns true when the ray hits the triangle at tmin < t <= tmax (closed at tmax so callers can
// break ties in t by primitive id). u, v are the barycentrics of v1 and v2. The steps and their
// rounding follow host/bvh/triangle_intersect.cpp one for one; `precise` forbids the fused
// multiply-adds that would break the bit-exact antisymmetry of shared edges [WBW §3].
bool intersectTriangle(WatertightRay r, vec3 p0, vec3 p1, vec3 p2, float tmin, float tmax,
                       out float t, out float u, out float v) {
  precise vec3 A = p0 - r.origin;
  precise vec3 B = p1 - r.origin;
  precise vec3 C = p2 - r.origin;
  vec3 a = shearVertex(r, A), b = shearVertex(r, B), c = shearVertex(r, C);
  float Ax = a.x, Ay = a.y, Bx = b.x, By = b.y, Cx = c.x, Cy = c.y;
  // Scaled barycentrics: U weighs v0 (edge v1-v2), V weighs v1, W weighs v2 [WBW §3.2].
  float U = edgeFunction(Cx, By, Cy, Bx);
  float V = edgeFunction(Ax, Cy, Ay, Cx);
  float W = edgeFunction(Bx, Ay, By, Ax);
  t = 0.0;
  u = 0.0;
  v = 0.0;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  precise float det = U + V + W;
  if (det == 0.0) return false;
  float Az = a.z, Bz = b.z, Cz = c.z;
  precise float T = (U * Az + V * Bz) + W * Cz;
  // Divide, then test the rounded t (not T against tmax*det): acceptance then depends on the
  // (ray, triangle) pair alone, not on the order in which a traversal tightened tmax.
  t = T / det;
  u = V / det;
  v = W / det;
  // A t that rounding could have made positive is no hit [PBR3 §3.9.5]: for a huge triangle the
  // error of t grows with its vertices, so the origin offset of a secondary ray cannot cover it.
  float zScale = abs(r.shear.z);
  float tError = triangleTError(Ax, Ay, Az, Bx, By, Bz, Cx, Cy, Cz, U, V, W, det, zScale);
  return t > tmin && t > tError && t <= tmax;
}

// Direction reciprocal for slab tests. A zero component becomes a huge finite value of the same
// sign instead of inf, so (bound - origin) * inv is never 0 * inf = NaN. Such a ray stays in the
// slab of that axis exactly when lo <= origin <= hi; the boxes are widened by one ulp on the
// host (render::widenBox) so that an origin exactly on a face gives a nonzero, hence huge,
// (bound - origin) * inv of the right sign.
vec3 safeReciprocal(vec3 d) {
  const float kTiny = 1e-37;
  vec3 m = max(abs(d), vec3(kTiny));
  return vec3(d.x < 0.0 ? -1.0 : 1.0, d.y < 0.0 ? -1.0 : 1.0, d.z < 0.0 ? -1.0 : 1.0) / m;
}


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
