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
bool meetsShaft(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 lc, vec3 lh) {
  vec3 d = lc - ac;
  vec3 axes[6] = vec3[6](vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1), vec3(0.0, -d.z, d.y), vec3(d.z, 0.0, -d.x),
                         vec3(-d.y, d.x, 0.0));
  for (uint i = 0u; i < 6u; ++i) {
    vec3 n = axes[i];
    if (dot(n, n) == 0.0) continue;
    vec2 a = project(ac, ah, n), l = project(lc, lh, n);
    if (apart(project(bc, bh, n), vec2(min(a.x, l.x), max(a.y, l.y)))) return false;
  }
  return true;
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
