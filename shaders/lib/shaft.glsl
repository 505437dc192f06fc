// shaft.glsl — whether a box can meet a segment from one box to another (the paper's shafts,
// Haines & Wallace 1994): dirty.comp's bounds and the probing passes' test of a shading point's
// shadow rays (lib/shading_bindings.glsl, probeShadowRaysMayMeet).
#ifndef OBSCURA_SHAFT_GLSL
#define OBSCURA_SHAFT_GLSL

// The interval a box (centre c, half extent h) projects to on axis n.
vec2 project(vec3 c, vec3 h, vec3 n) {
  float m = dot(c, n), r = dot(h, abs(n));
  return vec2(m - r, m + r);
}

bool apart(vec2 a, vec2 b) { return a.y < b.x || b.y < a.x; }

// Whether box B can meet a segment from box A to box L. Every such segment lies in the convex hull
// of A and L (the paper's shaft, Haines & Wallace 1994), whose projection on any axis is the hull
// of A's and L's projections; B misses the hull when its projection misses that on some axis. The
// axes: x, y, z and three across the shaft's direction, which make a long shaft thin.
// Written out axis by axis, without an array of axes: on lavapipe a local array indexed in a loop
// is a per-lane gather, and dirty.comp runs this for every pixel, light and changed box.
bool apartAcross(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 lc, vec3 lh, vec3 n) {
  if (dot(n, n) == 0.0) return false;
  vec2 a = project(ac, ah, n), l = project(lc, lh, n);
  return apart(project(bc, bh, n), vec2(min(a.x, l.x), max(a.y, l.y)));
}

bool meetsShaft(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 lc, vec3 lh) {
  // x, y, z: the hull projects as the union of A's and L's boxes.
  vec3 lo = min(ac - ah, lc - lh), hi = max(ac + ah, lc + lh);
  if (any(lessThan(bc + bh, lo)) || any(lessThan(hi, bc - bh))) return false;
  vec3 d = lc - ac;
  return !apartAcross(bc, bh, ac, ah, lc, lh, vec3(0.0, -d.z, d.y)) &&
         !apartAcross(bc, bh, ac, ah, lc, lh, vec3(d.z, 0.0, -d.x)) &&
         !apartAcross(bc, bh, ac, ah, lc, lh, vec3(-d.y, d.x, 0.0));
}

// The same for a directional light: box A swept to infinity along -direction. Across the direction
// the sweep projects as A does; along it, it reaches from A's far end towards the light.
bool meetsInfiniteShaft(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 direction) {
  vec3 d = -direction;
  vec3 axes[3] = vec3[3](vec3(0.0, -d.z, d.y), vec3(d.z, 0.0, -d.x), vec3(-d.y, d.x, 0.0));
  for (uint i = 0u; i < 3u; ++i)
    if (dot(axes[i], axes[i]) > 0.0 && apart(project(bc, bh, axes[i]), project(ac, ah, axes[i]))) return false;
  vec2 a = project(ac, ah, d);
  return project(bc, bh, d).y >= a.x;
}

#endif
