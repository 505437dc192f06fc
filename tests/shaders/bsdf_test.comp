#version 460
// Runs the production bsdf.glsl (and the GGX part of sampling.glsl) so tests/shaders/bsdf_test.cpp
// can compare it with the C++ twins (host/shading/bsdf.h) and check sampleBsdf's distribution.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/bsdf.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { uvec4 params; }; // x = case count

struct BsdfCase {
  vec4 material; // rgb base colour, w = metallic
  vec4 wo;       // xyz, w = roughness
  vec4 wi;       // xyz
  vec4 u;        // xyz = u3 for sampleBsdf
  uvec4 mode;    // x = kModeEval / kModeSample, y = seed
};
const uint kModeEval = 0u;   // r[0..6], see main()
const uint kModeSample = 1u; // kOutPerCase samples (rng.glsl): xyz = wi, w = pdf (0: none, < 0: delta)
const uint kOutPerCase = 16u;

layout(std430, binding = 0) readonly buffer Cases { BsdfCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; }; // kOutPerCase per case

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.x) return;
  BsdfCase c = cases[i];
  uint base = i * kOutPerCase;
  for (uint k = 0u; k < kOutPerCase; ++k) results[base + k] = vec4(0.0);
  vec3 color = c.material.rgb;
  float metallic = c.material.w, roughness = c.wo.w;
  vec3 wo = c.wo.xyz, wi = c.wi.xyz;
  if (c.mode.x == kModeEval) {
    results[base + 0u] = vec4(evalBsdf(color, metallic, roughness, wo, wi), bsdfPdf(color, metallic, roughness, wo, wi));
    vec3 sampled;
    float pdf;
    bool delta;
    vec3 weight = sampleBsdf(color, metallic, roughness, wo, c.u.xyz, sampled, pdf, delta);
    results[base + 1u] = vec4(weight, pdf);
    results[base + 2u] = vec4(sampled, delta ? 1.0 : 0.0);
    results[base + 3u] = vec4(evalBsdf(color, metallic, roughness, wo, sampled),
                              bsdfPdf(color, metallic, roughness, wo, sampled));
    float alpha = ggxAlpha(roughness);
    results[base + 4u] = vec4(ggxD(wi.z, alpha), smithG1(wo.z, alpha), smithG2(wo.z, wi.z, alpha),
                              ggxReflectionPdf(wo, wi, alpha));
    vec3 h = sampleGgxVisibleNormal(wo, alpha, c.u.yz);
    results[base + 5u] = vec4(h, ggxVisibleNormalPdf(wo, h, alpha));
    results[base + 6u] = vec4(isGlossy(metallic, roughness) ? 1.0 : 0.0, isMirror(roughness) ? 1.0 : 0.0,
                              specularProbability(color, metallic, wo.z), alpha);
    vec3 weight7;
    float pdf7;
    vec3 wi7;
    weight7 = sampleBsdf(color, metallic, roughness, wo, c.u.xyz, wi7, pdf7); // the 7-argument form
    results[base + 7u] = vec4(weight7, pdf7);
    results[base + 8u] = vec4(ggxD(wo + wi, alpha), 0.0, 0.0, 0.0);
  } else {
    uint state = pcgHash(c.mode.y ^ pcgHash(i));
    for (uint k = 0u; k < kOutPerCase; ++k) {
      vec3 u3 = vec3(rngNext(state), rngNext(state), rngNext(state));
      vec3 sampled;
      float pdf;
      bool delta;
      sampleBsdf(color, metallic, roughness, wo, u3, sampled, pdf, delta);
      results[base + k] = vec4(sampled, delta ? -pdf : pdf);
    }
  }
}
