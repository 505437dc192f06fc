// mis.glsl — multiple importance sampling between light sampling (lights.glsl sampleLight) and
// BSDF sampling (bsdf.glsl sampleBsdf), for the path tracer [SPEC §1.5].
// Needs the light bindings (`lights[]`) declared by the including shader, like lights.glsl.
//
// Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering",
// SIGGRAPH 1995: one sample from each of two techniques, weighted by the power heuristic
// (exponent 2). Only area lights take part: punctual lights cannot be hit by a BSDF-sampled ray,
// and a mirror's delta lobe cannot be sampled by a light, so both get weight 1 in the only
// technique that can produce them.
#ifndef OBSCURA_MIS_GLSL
#define OBSCURA_MIS_GLSL

// w_a = p_a^2 / (p_a^2 + p_b^2) for one sample of technique a; 1 when p_b is 0, 0 when p_a is 0.
// Written as a ratio so that large pdfs (narrow GGX lobes, ~1e5) cannot overflow when squared.
float powerHeuristic(float pa, float pb) {
  if (pa <= 0.0) return 0.0;
  if (pb <= 0.0) return 1.0;
  float r = pb / pa;
  return 1.0 / (1.0 + r * r);
}

// The solid-angle density with which sampleLight() (lights.glsl) picks the point y on light
// `light` (an area light) seen from a shading point at squared distance dist2, with |cos| cosL at
// y: selection probability x (1 / group area) x r^2 / cos(theta_L). Triangles are picked by area
// and points uniformly on them, so the point density over the group is 1 / group area, whichever
// triangle it lies on. 0 for a light that is never sampled, or one that is not an area light.
float areaLightPdf(uint light, float dist2, float cosL) {
  GpuLight l = lights[light];
  float groupArea = uintBitsToFloat(l.info.w);
  if (l.info.x != kLightArea || !(groupArea > 0.0) || !(cosL > 0.0)) return 0.0;
  return l.params.y / groupArea * dist2 / cosL;
}

#endif
