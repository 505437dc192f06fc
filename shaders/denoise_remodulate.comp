#version 460
// denoise_remodulate.comp — the denoised image: the filtered direct and ambient terms times the
// albedo they were divided by (denoise_gather.comp), plus the filtered specular light and the seen
// emission, which was never filtered: C = (D' + A') max(a, floor) + S' + emission, with the
// samples it counts for in w. denoise_edges.comp resolves the pixels an edge crosses from it.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(std430, binding = kBindingDenoiseParams) readonly buffer Params { DenoiseParams params; };
layout(binding = kBindingRemodulateGuide) uniform usamplerBuffer guide;
layout(binding = kBindingRemodulateIllum) uniform usamplerBuffer illum;
layout(std430, binding = kBindingRemodulateEmission) readonly buffer Emission { vec4 emission[]; };
layout(std430, binding = kBindingRemodulateOut) writeonly buffer Out { vec4 remodulated[]; };

void main() {
  const uint pixel = gl_GlobalInvocationID.x;
  if (pixel >= params.frame.x * params.frame.y) return;
  const Guide g = decodeGuide(texelFetch(guide, int(pixel)));
  const Illum f = readIllum(illum, pixel, true); // the second texel for the sample count
  const vec3 specular = params.frame.w != 0u ? f.specular : vec3(0.0);
  remodulated[pixel] = vec4((f.direct + f.ambient) * demodulationAlbedo(g) + specular + emission[pixel].rgb, f.samples);
}
