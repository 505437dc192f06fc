// mis.glsl — multiple importance sampling between light sampling (lights.glsl sampleLight) and
// BSDF sampling (bsdf.glsl sampleBsdf, or the specular lobe alone in specular.comp).
// Needs bvh.glsl (the triangle of a hit) and lights.glsl.
//
// Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering",
// SIGGRAPH 1995: n_a samples of technique a and n_b of technique b, each weighted by the power
// heuristic (exponent 2). Only area lights take part: punctual lights cannot be hit by a
// BSDF-sampled ray, and a mirror's delta lobe cannot be sampled by a light, so both get weight 1
// in the only technique that can produce them.
#ifndef OBSCURA_MIS_GLSL
#define OBSCURA_MIS_GLSL

// w_a = (n_a p_a)^2 / ((n_a p_a)^2 + (n_b p_b)^2) for one sample of technique a; pass p_a and p_b
// already multiplied by their sample counts. 1 when p_b is 0, 0 when p_a is 0. Written as a ratio
// so that large pdfs (narrow GGX lobes, ~1e5) cannot overflow when squared.
float powerHeuristic(float pa, float pb) {
  if (pa <= 0.0) return 0.0;
  if (pb <= 0.0) return 1.0;
  float r = pb / pa;
  return 1.0 / (1.0 + r * r);
}

// The solid-angle density with which light sampling at vertex (p, n) would have picked the point
// `y` where a BSDF-sampled ray along `direction` hit an emitter of light group `light`.
float emitterHitLightPdf(uint light, vec3 p, vec3 n, uint lightCount, RayHit hit, vec3 y, vec3 direction) {
  int base = triangleTexel(hit);
  vec3 v0 = texelFetch(bvhItems, base).xyz;
  vec3 v1 = texelFetch(bvhItems, base + 1).xyz;
  vec3 v2 = texelFetch(bvhItems, base + 2).xyz;
  vec3 d = y - p;
  float cosL = abs(dot(normalize(cross(v1 - v0, v2 - v0)), direction));
  return areaLightPdf(light, p, n, lightCount, v0, v1, v2, dot(d, d), cosL);
}

#endif
