// lights.glsl — the one direct-light estimator's sampling half: choosing a light and a point on it
// for a shadow ray [RTO §4.1 step 2, SPEC §1.3], and the density of that choice (for MIS).
// Needs light_bindings.glsl (lightAt, emitterAt), the light tree (kBindingLightTree) declared by
// the including shader as `lightTree[]`, and sampling.glsl.
//
// Two estimators (kLightSampling* in host_device.h), chosen per dispatch through gLightSampling:
// - Spatial (default): light i with probability importance_i(P, n) / sum_j importance_j(P, n)
//   (lightImportance below) up to kMaxSpatialLights lights, by a descent of the light tree with
//   the same importance on its nodes beyond; on an area light a triangle by area, then a direction uniform in the
//   triangle's solid angle (Arvo 1995), so the estimator has no 1/r^2 at small emitters; area
//   sampling only where the solid angle is too small for the spherical warp's float precision or
//   too large (more than a hemisphere) for it.
// - Area: the paper's [RTO §4.1]: light i with probability power_i / sum_j power_j, a triangle by
//   area and a point uniform on it.
// Both stay linear in every emission: the probabilities use the lights' render-time powers, never
// the compose-time emissions, and each sample lands in the basis buffer of the light it chose.
#ifndef OBSCURA_LIGHTS_GLSL
#define OBSCURA_LIGHTS_GLSL

// The estimator of this dispatch (set by main() from its push constants).
uint gLightSampling = kLightSamplingSpatial;

// Solid angles between which a triangle is sampled by Arvo's warp [sr]: below, its angles lose
// float precision (pbrt-v4 uses the same bounds, §6.5.4); above, the triangle covers more than a
// hemisphere seen from the point.
const float kMinSphericalSampleArea = 3e-4;
const float kMaxSphericalSampleArea = 6.22;

struct LightSample {
  uint light;       // index of the light (and of its basis buffer)
  vec3 wi;          // unit direction from the shading point to the light
  vec3 target;      // the point the shadow ray must reach (tmax = its distance)
  vec3 targetNormal;// for area lights: the light's geometric normal facing the shading point
  bool infinite;    // directional light or background: no target point
  bool hittable;    // a BSDF-sampled ray can reach it too (area light, background): MIS applies
  vec3 weight;      // unit-emission radiance x geometry / pdf: multiply by the BRDF and cos(P)
  float pdf;        // solid-angle pdf (area lights), or the selection probability (punctual)
};

// ---- Choosing the light

// First light whose selection CDF by power exceeds u (zero-power lights have empty intervals).
uint selectLightByPower(float u, uint count) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (u < lightAt(mid).params.x) hi = mid; else lo = mid + 1u;
  }
  return lo;
}

uint selectEmitter(float u, uint first, uint count) {
  uint lo = first, hi = first + count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (u < emitterAt(mid).v0.w) hi = mid; else lo = mid + 1u;
  }
  return lo;
}

// cos(max(0, A - B)) from the cosines and sines of A and B in [0, pi].
float cosOfClampedDifference(float cosA, float sinA, float cosB, float sinB) {
  return cosA >= cosB ? 1.0 : cosA * cosB + sinA * sinB;
}
float sinOfClampedDifference(float cosA, float sinA, float cosB, float sinB) {
  return cosA >= cosB ? 0.0 : sinA * cosB - cosA * sinB;
}

// An upper bound on the light that lights of total power `power` within the bounding sphere
// `sphere` (xyz centre, w radius), emitting within `cone` (axis xyz, w = cos theta_o; -1: any
// direction) widened by theta_e (cosE), can send to a receiver at p with normal n (facing the side
// that reflects), up to a common factor: power x cos(theta') x cos(theta_i') / d^2, where theta'
// is the smallest angle between the emission cone and the direction to p, and theta_i' the
// smallest angle between n and a direction into the sphere (Conty Estevez & Kulla, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting", HPG 2018, eq. 3, as in pbrt-v4's
// LightBounds::Importance, with a sphere for the box). A spot is uniform in its cone
// (uniformInCone: no cos(theta') factor, nothing past theta_o + theta_e). It is 0 only where the
// lights cannot reach p's reflecting side, so selection by it stays unbiased. One light
// (lightImportance) and one node of the light tree (nodeImportance) are bounded by this same
// function.
float boundsImportance(float power, vec4 sphere, vec4 cone, float cosE, bool uniformInCone, vec3 p, vec3 n) {
  if (!(power > 0.0)) return 0.0;
  vec3 toLight = sphere.xyz - p;
  float d2 = dot(toLight, toLight);
  float radius = sphere.w;
  float r2 = radius * radius;
  if (d2 <= r2 * 1.0001 || d2 == 0.0) return power / max(r2, 1e-12); // p inside the bounds
  float d = sqrt(d2);
  vec3 w = toLight / d;
  // The cone of directions from p into the bounding sphere.
  float sinB = radius / d, cosB = sqrt(max(0.0, 1.0 - sinB * sinB));
  // Receiver: the light must be above p's surface.
  float cosI = dot(n, w), sinI = sqrt(max(0.0, 1.0 - cosI * cosI));
  float cosIPrime = cosOfClampedDifference(cosI, sinI, cosB, sinB);
  if (cosIPrime <= 0.0) return 0.0;
  float importance = power * cosIPrime / d2;
  float cosO = cone.w;
  if (cosO > -1.0) {
    // Emitter: the angle between p (seen from the light) and the cone of emission directions.
    float sinO = sqrt(max(0.0, 1.0 - cosO * cosO));
    float cosW = dot(cone.xyz, -w), sinW = sqrt(max(0.0, 1.0 - cosW * cosW));
    float cosX = cosOfClampedDifference(cosW, sinW, cosO, sinO);
    float sinX = sinOfClampedDifference(cosW, sinW, cosO, sinO);
    float cosPrime = cosOfClampedDifference(cosX, sinX, cosB, sinB);
    // An area light emits within 90 degrees of its normals (cosE = 0); a spot nowhere past its
    // outer cone (cosE = kSpotConeSlack, rounding slack).
    if (uniformInCone ? cosPrime < cosE : cosPrime <= cosE) return 0.0;
    importance *= uniformInCone ? 1.0 : cosPrime;
  }
  return importance;
}

// Light i's importance: its own bounds (the area light's sphere and normal cone, a point, a spot's
// position and outer cone). Directional lights are not bounded here (lightSelection gives them
// their own share).
float lightImportance(uint i, vec3 p, vec3 n) {
  GpuLight light = lightAt(i);
  uint type = light.info.x;
  bool area = type == kLightArea, spot = type == kLightSpot;
  vec4 sphere = vec4(light.position.xyz, area ? light.position.w : 0.0);
  vec4 cone = area ? light.direction : spot ? vec4(light.direction.xyz, light.params.w) : vec4(0.0, 0.0, 1.0, -1.0);
  return boundsImportance(light.params.y, sphere, cone, spot ? kSpotConeSlack : 0.0, spot, p, n);
}

// Lights without bounds: directional lights and the background. They get an equal share of the
// selection among themselves and the bounded lights as one (pbrt-v4's BVHLightSampler does the
// same for infinite lights).
bool isUnbounded(uint type) { return type == kLightDirectional || type == kLightBackground; }

// Up to kMaxSpatialLights lights, the spatial selection weighs every light at the point (exact);
// beyond, it descends the light tree (approximate weights, a bounded number of nodes).
// A kernel specialised with kFlatLightSelection uses only the flat selection (the host makes
// sure that the dispatch samples spatially and that count <= kMaxSpatialLights).
layout(constant_id = kSpecConstantFlatLightSelection) const bool kFlatLightSelection = false;
bool useSpatialSelection(uint count) {
  return kFlatLightSelection || (gLightSampling == kLightSamplingSpatial && count <= kMaxSpatialLights);
}
bool useLightTree(uint count) {
  return !kFlatLightSelection && gLightSampling == kLightSamplingSpatial && count > kMaxSpatialLights;
}

// ---- The light tree (more than kMaxSpatialLights lights; layout: GpuLightNode in host_device.h)
// Stochastic descent (Conty Estevez & Kulla 2018 §4; pbrt-v4's BVHLightSampler::Sample): from the
// root, each internal node is left for one of its two children with probability proportional to
// the child's importance at p, n (boundsImportance on the child's bounds), and u is rescaled into
// the chosen child's interval, so one number drives the whole descent. A light's probability is
// the product of the choices on its path; lightTreePdf walks that path again from the light's bit
// trail. Unbounded lights keep the equal share they have in the flat selection.

float nodeImportance(uint row, vec3 p, vec3 n) {
  GpuLightNode node = lightTree[row];
  return boundsImportance(node.emission.x, node.sphere, node.cone, node.emission.y, node.emission.z != 0.0, p, n);
}

// The probabilities of going from the internal node with children `refs.xy` to each child.
vec2 lightTreeChildProbabilities(uvec4 refs, vec3 p, vec3 n) {
  float a = nodeImportance(refs.x, p, n), b = nodeImportance(refs.y, p, n);
  float total = a + b;
  return total > 0.0 ? vec2(a / total, b / total) : vec2(0.0);
}

// The number of equal shares at p: one per unbounded light with power, one for the tree where its
// root can light p (`lit`).
float lightTreeShares(vec3 p, vec3 n, out bool lit) {
  uvec4 header = lightTree[0].refs;
  lit = header.x != kInvalidIndex && nodeImportance(header.x, p, n) > 0.0;
  return float(header.y) + (lit ? 1.0 : 0.0);
}

uint selectLightFromTree(float u, vec3 p, vec3 n, out float selection) {
  uvec4 header = lightTree[0].refs;
  bool lit;
  float shares = lightTreeShares(p, n, lit);
  selection = 0.0;
  if (shares == 0.0) return 0u;
  // u in [0, unbounded / shares): the k-th unbounded light; beyond: down the tree.
  float scaled = u * shares;
  uint unbounded = header.y;
  if (!lit || scaled < float(unbounded)) {
    selection = 1.0 / shares;
    return lightTree[1u + header.z + min(uint(scaled), unbounded - 1u)].refs.x;
  }
  float v = min(scaled - float(unbounded), kOneMinusEpsilon);
  float probability = 1.0 / shares;
  uint row = header.x;
  for (uint depth = 0u; depth < kLightTreeMaxDepth; ++depth) {
    uvec4 refs = lightTree[row].refs;
    if (refs.y == kInvalidIndex) break; // a leaf
    vec2 q = lightTreeChildProbabilities(refs, p, n);
    bool second = !(v < q.x);
    probability *= second ? q.y : q.x;
    if (!(probability > 0.0)) return 0u; // neither child can light p
    v = min(second ? (v - q.x) / q.y : v / q.x, kOneMinusEpsilon);
    row = second ? refs.y : refs.x;
  }
  selection = probability;
  return lightTree[row].refs.x;
}

// The probability that selectLightFromTree picks light `chosen` at p, n: the same choices, taken
// along the light's trail.
float lightTreePdf(uint chosen, vec3 p, vec3 n) {
  bool lit;
  float shares = lightTreeShares(p, n, lit);
  if (shares == 0.0) return 0.0;
  if (isUnbounded(lightAt(chosen).info.x)) return lightAt(chosen).params.y > 0.0 ? 1.0 / shares : 0.0;
  uvec4 leaf = lightTree[1u + chosen].refs;
  if (!lit || leaf.w == kInvalidIndex) return 0.0;
  float probability = 1.0 / shares;
  uint row = lightTree[0].refs.x;
  for (uint depth = 0u; depth < leaf.w; ++depth) {
    uvec4 refs = lightTree[row].refs;
    vec2 q = lightTreeChildProbabilities(refs, p, n);
    bool second = ((leaf.z >> depth) & 1u) != 0u;
    probability *= second ? q.y : q.x;
    row = second ? refs.y : refs.x;
  }
  return probability;
}

// ---- The flat selection (up to kMaxSpatialLights lights)

// The spatial selection's weights at one shading point: every bounded light's importance, their
// sum and the number of unbounded lights with power. A hit draws several light samples (N_s shadow
// rays, the specular pass's vertex samples, MIS densities of lobe rays that reach a light) from the
// same p and n, so the weights are computed once per point and kept here: the per-sample cost is a
// walk over stored numbers, not `count` importance evaluations (each loads a light's bounds and
// takes a few square roots), and lavapipe's loop limiter is charged once per point. The
// numbers are the ones every sample would compute, in the same order, so images are unchanged.
float gImportance[kMaxSpatialLights];
// gImportanceCdf[i]: the running sum of the weights of lights 0..i, added in that order (the sum
// the linear walk of selectLight used to form), so a binary search finds the same light.
float gImportanceCdf[kMaxSpatialLights];
uint gImportanceLastLit = 0u; // the last light with a weight > 0 (takes a target rounded past the sum)
float gImportanceTotal = 0.0;
uint gImportanceDirectional = 0u;
bool gImportanceValid = false;
vec3 gImportanceP = vec3(0.0);
vec3 gImportanceN = vec3(0.0);
uint gImportanceCount = 0u;

void prepareLightImportances(vec3 p, vec3 n, uint count) {
  if (gImportanceValid && p == gImportanceP && n == gImportanceN && count == gImportanceCount) return;
  gImportanceValid = true;
  gImportanceP = p;
  gImportanceN = n;
  gImportanceCount = count;
  gImportanceTotal = 0.0;
  gImportanceDirectional = 0u;
  for (uint i = 0u; i < count; ++i) {
    float w = 0.0;
    if (isUnbounded(lightAt(i).info.x)) gImportanceDirectional += lightAt(i).params.y > 0.0 ? 1u : 0u;
    else w = lightImportance(i, p, n);
    gImportance[i] = w;
    gImportanceTotal += w;
    gImportanceCdf[i] = gImportanceTotal;
    gImportanceLastLit = w > 0.0 ? i : gImportanceLastLit;
  }
}

// The probability that the estimator picks light `chosen` at p with normal n.
float lightSelectionPdf(uint chosen, vec3 p, vec3 n, uint count) {
  if (useLightTree(count)) return lightTreePdf(chosen, p, n);
  if (!useSpatialSelection(count)) return lightAt(chosen).params.y;
  prepareLightImportances(p, n, count);
  float total = gImportanceTotal;
  float shares = float(gImportanceDirectional) + (total > 0.0 ? 1.0 : 0.0);
  if (shares == 0.0) return 0.0;
  if (isUnbounded(lightAt(chosen).info.x)) return lightAt(chosen).params.y > 0.0 ? 1.0 / shares : 0.0;
  return total > 0.0 ? gImportance[chosen] / total / shares : 0.0;
}

// Picks a light for p with normal n; selection = its probability (0: no light can light p).
uint selectLight(float u, vec3 p, vec3 n, uint count, out float selection) {
  if (useLightTree(count)) return selectLightFromTree(u, p, n, selection);
  if (!useSpatialSelection(count)) {
    uint chosen = selectLightByPower(u, count);
    selection = lightAt(chosen).params.y;
    return chosen;
  }
  prepareLightImportances(p, n, count);
  float total = gImportanceTotal;
  uint directional = gImportanceDirectional;
  float shares = float(directional) + (total > 0.0 ? 1.0 : 0.0);
  selection = 0.0;
  if (shares == 0.0) return 0u;
  // u in [0, directional / shares): the k-th directional light; beyond: bounded lights by importance.
  float scaled = u * shares;
  if (scaled < float(directional)) {
    uint k = min(uint(scaled), directional - 1u);
    for (uint i = 0u; i < count; ++i) {
      if (!isUnbounded(lightAt(i).info.x) || !(lightAt(i).params.y > 0.0)) continue;
      if (k == 0u) {
        selection = 1.0 / shares;
        return i;
      }
      --k;
    }
    return 0u;
  }
  float target = (scaled - float(directional)) * total;
  // The first light whose running sum exceeds target, by bisection of the stored sums (a light
  // of weight 0 repeats the sum before it, so the first sum above target is always a light with
  // weight). Where rounding leaves target at or past the sum, the last light with weight takes it.
  // Same light as walking the weights one by one, in log2(count) steps instead of count.
  uint lo = 0u, hi = count;
  while (lo < hi) {
    uint mid = (lo + hi) >> 1;
    if (target < gImportanceCdf[mid]) hi = mid;
    else lo = mid + 1u;
  }
  uint chosen = lo < count ? lo : gImportanceLastLit;
  selection = gImportance[chosen] / total / shares;
  return chosen;
}

// ---- The point on the light

// glTF KHR_lights_punctual: smooth range window and the spot cone's smooth falloff.
float rangeWindow(float distance, float range) {
  if (range <= 0.0) return 1.0;
  float r = distance / range;
  float w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
  return w * w;
}

float spotFalloff(GpuLight light, vec3 wi) {
  float cd = dot(light.direction.xyz, -wi);
  float cosInner = light.params.z, cosOuter = light.params.w;
  float t = clamp((cd - cosOuter) / max(cosInner - cosOuter, 1e-4), 0.0, 1.0);
  return t * t;
}

// Whether the spatial estimator samples triangle (v0, v1, v2) from p by solid angle; its solid
// angle in `solidAngle`. The same test decides the pdf of a point reached by BSDF sampling.
bool sampleBySolidAngle(vec3 p, vec3 v0, vec3 v1, vec3 v2, out vec3 a, out vec3 b, out vec3 c,
                        out float solidAngle) {
  a = normalize(v0 - p);
  b = normalize(v1 - p);
  c = normalize(v2 - p);
  solidAngle = sphericalTriangleArea(a, b, c);
  return gLightSampling == kLightSamplingSpatial && solidAngle >= kMinSphericalSampleArea &&
         solidAngle <= kMaxSphericalSampleArea;
}

// A point on light `chosen` seen from p with normal n, picked with probability `selection` (1 when
// it is sampled alone); u.yzw: the triangle (by area) and the point on it; for the background, u.zw
// a direction by the cosine about n.
LightSample sampleChosenLight(vec3 p, vec3 n, vec4 u, uint chosen, float selection) {
  LightSample s;
  s.light = chosen;
  GpuLight light = lightAt(s.light);
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.infinite = false;
  s.targetNormal = vec3(0.0);
  s.wi = vec3(0.0, 0.0, 1.0);
  s.target = p;
  s.hittable = light.info.x == kLightArea || light.info.x == kLightBackground;
  if (!(selection > 0.0)) return s;
  uint type = light.info.x;
  if (type == kLightBackground) {
    // Unit radiance from every direction: cosine-distributed about n (pdf cos / pi), so an open
    // Lambertian surface's estimate has no variance at all.
    vec3 t, b;
    orthonormalBasis(n, t, b);
    vec3 local = sampleCosineHemisphere(u.zw);
    s.wi = toWorld(local, t, b, n);
    s.infinite = true;
    s.pdf = selection * cosineHemispherePdf(local.z);
    s.weight = s.pdf > 0.0 ? vec3(1.0 / s.pdf) : vec3(0.0);
    return s;
  }
  if (type == kLightArea) {
    uint e = selectEmitter(u.y, light.info.y, light.info.z);
    GpuEmitter em = emitterAt(e);
    float groupArea = uintBitsToFloat(light.info.w);
    float triangleShare = em.v1.w / groupArea; // probability of this triangle
    vec3 ny = normalize(cross(em.v1.xyz - em.v0.xyz, em.v2.xyz - em.v0.xyz));
    bool front = dot(p - em.v0.xyz, ny) > 0.0;
    if (!front && em.v2.w == 0.0) return s; // one-sided, seen from behind [SPEC §5]
    vec3 a, b, c;
    float solidAngle;
    if (sampleBySolidAngle(p, em.v0.xyz, em.v1.xyz, em.v2.xyz, a, b, c, solidAngle)) {
      vec3 w = sampleSphericalTriangle(u.zw, a, b, c);
      float cosL = abs(dot(ny, w));
      float t = dot(em.v0.xyz - p, ny) / dot(w, ny); // where w meets the triangle's plane
      if (!(t > 0.0) || !(cosL > 0.0) || isinf(t)) return s;
      s.wi = w;
      s.target = p + t * w;
      s.targetNormal = front ? ny : -ny;
      s.pdf = selection * triangleShare / solidAngle;
      s.weight = em.radiance.rgb / s.pdf;
      return s;
    }
    vec3 y = sampleUniformTriangle(u.zw, em.v0.xyz, em.v1.xyz, em.v2.xyz);
    vec3 d = y - p;
    float dist2 = dot(d, d);
    s.wi = d * inversesqrt(dist2);
    float cosL = abs(dot(ny, s.wi));
    s.target = y;
    s.targetNormal = front ? ny : -ny;
    // Area pdf of the point: selection x (A_tri / A_group) x (1 / A_tri).
    float pdfArea = selection / groupArea;
    s.pdf = pdfArea * dist2 / max(cosL, 1e-20);
    s.weight = pdfArea > 0.0 && cosL > 0.0 ? em.radiance.rgb * cosL / (dist2 * pdfArea) : vec3(0.0);
  } else if (type == kLightDirectional) {
    s.wi = -light.direction.xyz;
    s.infinite = true;
    s.target = p;
    s.pdf = selection;
    s.weight = vec3(1.0 / selection);
  } else { // point or spot: irradiance intensity / r^2 (candela at unit scale)
    vec3 d = light.position.xyz - p;
    float dist2 = dot(d, d);
    float dist = sqrt(dist2);
    s.wi = d / dist;
    s.target = light.position.xyz;
    s.pdf = selection;
    float falloff = rangeWindow(dist, light.position.w) * (type == kLightSpot ? spotFalloff(light, s.wi) : 1.0);
    s.weight = vec3(falloff / (dist2 * selection));
  }
  return s;
}

// One light sample for shading point p with normal n (the side that reflects): the light, then a
// point on it (see the header). u = 4 uniform numbers.
LightSample sampleLight(vec3 p, vec3 n, vec4 u, uint lightCount) {
  float selection;
  uint chosen = selectLight(u.x, p, n, lightCount, selection);
  return sampleChosenLight(p, n, u, chosen, selection);
}

// The solid-angle density with which sampleLight(p, n, ...) picks the point y on triangle
// (v0, v1, v2) of area light `light` (y has |cos| cosL there, squared distance dist2 from p):
// selection x (A_tri / A_group) x (1 / solid angle, or r^2 / (cos A_tri) where area sampling).
// For MIS with BSDF sampling; 0 for a light that is never sampled, or not an area light.
float areaLightPdf(uint light, vec3 p, vec3 n, uint count, vec3 v0, vec3 v1, vec3 v2, float dist2, float cosL) {
  GpuLight l = lightAt(light);
  float groupArea = uintBitsToFloat(l.info.w);
  if (l.info.x != kLightArea || !(groupArea > 0.0) || !(cosL > 0.0)) return 0.0;
  float selection = lightSelectionPdf(light, p, n, count);
  if (!(selection > 0.0)) return 0.0;
  vec3 a, b, c;
  float solidAngle;
  if (sampleBySolidAngle(p, v0, v1, v2, a, b, c, solidAngle))
    return selection * triangleArea(v0, v1, v2) / groupArea / solidAngle;
  return selection / groupArea * dist2 / cosL;
}

// The background's slot among the first `count` lights, or kInvalidIndex.
uint findBackgroundLight(uint count) {
  for (uint i = 0u; i < count; ++i)
    if (lightAt(i).info.x == kLightBackground) return i;
  return kInvalidIndex;
}

// The solid-angle density with which sampleLight(p, n, ...) picks direction `dir` towards the
// background light `light` (for MIS with a BSDF-sampled ray that left the scene).
float backgroundLightPdf(uint light, vec3 p, vec3 n, uint count, vec3 dir) {
  return lightSelectionPdf(light, p, n, count) * max(dot(n, dir), 0.0) * (1.0 / kPi);
}

#endif
