// lights.glsl — choosing a light and a point on it for a shadow ray [RTO §4.1 step 2, SPEC §1.3].
// Needs the light bindings (kBindingLights, kBindingEmitters) declared by the including shader
// as `lights[]` and `emitters[]`, and sampling.glsl (kPi, sampleUniformTriangle).
#ifndef OBSCURA_LIGHTS_GLSL
#define OBSCURA_LIGHTS_GLSL


struct LightSample {
  uint light;       // index of the light (and of its basis buffer)
  vec3 wi;          // unit direction from the shading point to the light
  vec3 target;      // the point the shadow ray must reach (tmax = its distance)
  vec3 targetNormal;// for area lights: the light's geometric normal facing the shading point
  bool infinite;    // directional light: no target point
  vec3 weight;      // unit-emission radiance x geometry / pdf: multiply by the BRDF and cos(P)
  float pdf;        // solid-angle pdf (area lights), or the selection probability (punctual)
};

// First light whose selection CDF exceeds u (lights with zero power have empty intervals).
uint selectLight(float u, uint count) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (u < lights[mid].params.x) hi = mid; else lo = mid + 1u;
  }
  return lo;
}

uint selectEmitter(float u, uint first, uint count) {
  uint lo = first, hi = first + count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (u < emitters[mid].v0.w) hi = mid; else lo = mid + 1u;
  }
  return lo;
}

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

LightSample sampleChosenLight(vec3 p, vec4 u, uint chosen, float selection);

// One light sample for shading point p: light chosen with probability proportional to power,
// triangle proportional to area, point uniform on it [SPEC §1.3]. u = 4 uniform numbers.
LightSample sampleLight(vec3 p, vec4 u, uint lightCount) {
  uint chosen = selectLight(u.x, lightCount);
  return sampleChosenLight(p, u, chosen, lights[chosen].params.y);
}

// A point on light `chosen`, picked with probability `selection` (1 when it is sampled alone):
// triangle proportional to area, point uniform on it. u.x is not used.
LightSample sampleChosenLight(vec3 p, vec4 u, uint chosen, float selection) {
  LightSample s;
  s.light = chosen;
  GpuLight light = lights[s.light];
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.infinite = false;
  s.targetNormal = vec3(0.0);
  uint type = light.info.x;
  if (type == kLightArea) {
    uint e = selectEmitter(u.y, light.info.y, light.info.z);
    GpuEmitter em = emitters[e];
    float groupArea = uintBitsToFloat(light.info.w);
    vec3 y = sampleUniformTriangle(u.zw, em.v0.xyz, em.v1.xyz, em.v2.xyz);
    vec3 ny = normalize(cross(em.v1.xyz - em.v0.xyz, em.v2.xyz - em.v0.xyz));
    vec3 d = y - p;
    float dist2 = dot(d, d);
    s.wi = d * inversesqrt(dist2);
    float cosL = dot(ny, -s.wi);
    bool emits = cosL > 0.0 || em.v2.w != 0.0; // one-sided unless double-sided [SPEC §5]
    s.target = y;
    s.targetNormal = cosL > 0.0 ? ny : -ny;
    cosL = abs(cosL);
    // Area pdf of the point: selection x (A_tri / A_group) x (1 / A_tri).
    float pdfArea = selection / groupArea;
    s.pdf = pdfArea * dist2 / max(cosL, 1e-20);
    s.weight = emits && pdfArea > 0.0 && cosL > 0.0 ? em.radiance.rgb * cosL / (dist2 * pdfArea) : vec3(0.0);
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

#endif
