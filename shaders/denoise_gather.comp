#version 460
// denoise_gather.comp — the denoiser's input from one frame band (dispatched per band) into
// whole-frame buffers: the guide (mean normal, depth and albedo, the material of the first
// sample), the direct term sum_s E_s D_s and the ambient term I_a A divided by the albedo (so the
// filter never blurs a texture; Schied et al. 2017, §4.1 "demodulation"), the specular paths'
// light as it is, the sample count, and what is added back unfiltered (the seen emission).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/accumulate.glsl"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { DenoisePush pc; };
layout(std430, binding = kBindingDenoiseParams) readonly buffer Params { DenoiseParams params; };
layout(std430, binding = kBindingGatherComposed) readonly buffer Composed { vec4 composed[]; };
layout(std430, binding = kBindingGatherAovs) readonly buffer Aovs { vec4 aov[]; };
layout(std430, binding = kBindingGatherSampleCounts) readonly buffer SampleCounts { uint sampleCounts[]; };
layout(std430, binding = kBindingGatherGuide) writeonly buffer GuideOut { uvec4 guide[]; };
layout(std430, binding = kBindingGatherIllum) writeonly buffer IllumOut { uvec4 illum[]; };
layout(std430, binding = kBindingGatherEmission) writeonly buffer EmissionOut { vec4 emission[]; };

void main() {
  const uint local = gl_GlobalInvocationID.x;
  const uint width = params.frame.x, firstRow = pc.firstRow, rows = pc.rows, slots = pc.composedSlots;
  if (local >= width * rows) return;
  const uint pixel = firstRow * width + local;
  const uint samples = sampleCounts[local];
  const float inv = 1.0 / float(max(samples, 1u));
  const vec4 albedo = OBS_SUM(aov, local * kAovSlots + kAovAlbedo) * inv; // rgb, a = coverage
  const vec4 normalDepth = OBS_SUM(aov, local * kAovSlots + kAovNormal) * inv;
  const uint material = floatBitsToUint(OBS_SUM(aov, local * kAovSlots + kAovIds).y);

  const uvec4 packed = encodeGuide(pixelGuide(albedo, normalDepth, material));
  guide[pixel] = packed;

  // Divided by the albedo as remodulation will read it back (halves), so that an unfiltered pixel
  // comes back as it went in.
  const vec3 a = demodulationAlbedo(decodeGuide(packed));
  const uint o = local * slots;
  Illum i = noIllum();
  i.direct = composed[o + kComposeDirect].rgb / a;
  i.ambient = composed[o + kComposeIndirect].rgb / a;
  i.specular = composed[o + kComposeSpecular].rgb;
  i.samples = float(samples);
  OBS_WRITE_ILLUM(illum, pixel, i)
  emission[pixel] = vec4(composed[o + kComposeEmission].rgb, 0.0);
}
