#version 460
// compose.comp — the image from the basis buffers [SPEC §3], [IVR eq. 4]:
//   C = sum_s E_s D_s + I_a(E) A + emission (+ what specular paths gathered)
// Changing a light's E_s reruns this pass alone: relighting needs no ray.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/accumulate.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { ComposePush pc; };
layout(std430, binding = 0) readonly buffer Basis { vec4 basis[]; };      // [light * pixels + pixel]
layout(std430, binding = 1) readonly buffer Ambient { vec4 ambient[]; };  // rgb A sums, w W sums
layout(std430, binding = 2) readonly buffer Aovs { vec4 aov[]; };         // primary AOV sums
layout(std430, binding = 3) readonly buffer Scales { vec4 emission[]; };  // E_s per light
layout(std430, binding = 4) writeonly buffer Out { vec4 composed[]; };    // kComposeSlots per pixel
layout(std430, binding = 5) readonly buffer SpecularBasis { vec4 specularBasis[]; };
layout(std430, binding = 6) readonly buffer SpecularAmbient { vec4 specularAmbient[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint pixelCount = pc.frame.x * pc.frame.y;
  if (pixel >= pixelCount) return;
  float inv = 1.0 / float(max(pc.frame.z, 1u));
  vec3 direct = vec3(0.0);
  vec3 specular = vec3(0.0);
  const bool withSpecular = pc.ambient.w != 0.0;
  for (uint s = 0u; s < pc.frame.w; ++s) {
    direct += emission[s].rgb * OBS_SUM(basis, s * pixelCount + pixel).rgb;
    if (withSpecular) specular += emission[s].rgb * OBS_SUM(specularBasis, s * pixelCount + pixel).rgb;
  }
  direct *= inv;
  if (withSpecular) specular = (specular + pc.ambient.rgb * OBS_SUM(specularAmbient, pixel).rgb) * inv;
  vec4 a = OBS_SUM(ambient, pixel) * inv;
  vec3 indirect = pc.ambient.rgb * a.rgb;
  vec3 emitted = OBS_SUM(aov, pixel * kAovSlots + kAovEmission).rgb * inv;
  uint o = pixel * kComposeSlots;
  composed[o + kComposeCombined] = vec4(direct + indirect + emitted + specular, 1.0);
  composed[o + kComposeDirect] = vec4(direct, 1.0);
  composed[o + kComposeIndirect] = vec4(indirect, 1.0);
  composed[o + kComposeSpecular] = vec4(specular, 1.0);
  composed[o + kComposeObscurance] = vec4(a.w, a.w, a.w, 1.0);
}
