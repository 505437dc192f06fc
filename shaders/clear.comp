#version 460
// clear.comp — zeroes the shading sums (D_s, S_s, A, A^spec; Kahan pairs) of the dirty pixels of a
// band before they are retraced; primary.comp restarts the AOV and M_s sums at sample 0 itself.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { ClearPush pc; };
layout(std430, binding = kBindingClearDirty) readonly buffer Mask { uint dirty[]; };
layout(std430, binding = kBindingClearBasis) buffer Basis { vec4 basis[]; };
layout(std430, binding = kBindingClearAmbient) buffer Ambient { vec4 ambient[]; };
layout(std430, binding = kBindingClearSpecularBasis) buffer SpecularBasis { vec4 specularBasis[]; };
layout(std430, binding = kBindingClearSpecularAmbient) buffer SpecularAmbient { vec4 specularAmbient[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint pixelCount = pc.width * pc.rows;
  if (pixel >= pixelCount || dirty[pixel] == 0u) return;
  const bool withSpecular = pc.specular != 0u;
  for (uint s = 0u; s < pc.lightCount; ++s) {
    uint i = 2u * (s * pixelCount + pixel);
    basis[i] = vec4(0.0);
    basis[i + 1u] = vec4(0.0);
    if (withSpecular) {
      specularBasis[i] = vec4(0.0);
      specularBasis[i + 1u] = vec4(0.0);
    }
  }
  ambient[2u * pixel] = vec4(0.0);
  ambient[2u * pixel + 1u] = vec4(0.0);
  if (withSpecular) {
    specularAmbient[2u * pixel] = vec4(0.0);
    specularAmbient[2u * pixel + 1u] = vec4(0.0);
  }
}
