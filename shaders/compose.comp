#version 460
// compose.comp — the image from the basis buffers [SPEC §3], [IVR eq. 4]:
//   C = sum_s E_s (D_s + M_s) + I_a(E) A (+ what specular paths gathered, same form)
// D_s: direct light of light s at unit emission; M_s: the emission of light s the camera sees at
// unit emission; A: albedo x W_c. Changing a light's E_s reruns this pass alone: relighting
// needs no ray. Dispatched once per frame band.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/accumulate.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { ComposePush pc; };
// The Kahan sums through RGBA32F texel views (OBS_SUM_TEXEL): a quarter of the loads of an SSBO's.
layout(binding = kBindingComposeBasis) uniform samplerBuffer basis;
layout(binding = kBindingComposeAmbient) uniform samplerBuffer ambient;
layout(binding = kBindingComposeEmissionBasis) uniform samplerBuffer emissionBasis;
layout(std430, binding = kBindingComposeEmissions) readonly buffer Emissions { vec4 emission[]; };
layout(std430, binding = kBindingComposeOutput) writeonly buffer Out { vec4 composed[]; };
layout(binding = kBindingComposeSpecularBasis) uniform samplerBuffer specularBasis;
layout(binding = kBindingComposeSpecularAmbient) uniform samplerBuffer specularAmbient;
layout(std430, binding = kBindingComposeSampleCounts) readonly buffer SampleCounts { uint sampleCounts[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint pixelCount = pc.width * pc.rows;
  if (pixel >= pixelCount) return;
  float inv = 1.0 / float(max(sampleCounts[pixel], 1u));
  vec3 direct = vec3(0.0);
  vec3 seen = vec3(0.0);
  vec3 specular = vec3(0.0);
  const bool withSpecular = pc.specular != 0u;
  for (uint s = 0u; s < pc.lightCount; ++s) {
    vec3 e = emission[s].rgb;
    direct += e * OBS_SUM_TEXEL(basis, s * pixelCount + pixel).rgb;
    seen += e * OBS_SUM_TEXEL(emissionBasis, s * pixelCount + pixel).rgb;
    if (withSpecular) specular += e * OBS_SUM_TEXEL(specularBasis, s * pixelCount + pixel).rgb;
  }
  direct *= inv;
  seen *= inv;
  if (withSpecular) specular = (specular + pc.ambient * OBS_SUM_TEXEL(specularAmbient, pixel).rgb) * inv;
  vec4 a = OBS_SUM_TEXEL(ambient, pixel) * inv;
  vec3 indirect = pc.ambient * a.rgb;
  uint o = pixel * pc.slots;
  composed[o + kComposeCombined] = vec4(direct + indirect + seen + specular, 1.0);
  if (pc.slots == 1u) return; // only combined was asked for
  composed[o + kComposeDirect] = vec4(direct, 1.0);
  composed[o + kComposeIndirect] = vec4(indirect, 1.0);
  composed[o + kComposeSpecular] = vec4(specular, 1.0);
  composed[o + kComposeObscurance] = vec4(a.w, a.w, a.w, 1.0);
  composed[o + kComposeEmission] = vec4(seen, 1.0);
}
