#version 460
// correction_residual.comp — what the path-traced correction filters, from one band of the
// obscurance frame (dispatched per band) and the path tracer's sums (whole-frame) into whole-frame
// buffers: the guide (as the denoiser's gather makes it: mean normal, depth and albedo, the first
// sample's material), the obscurance frame's combined image, and the residual
//   r = (L_paths / n - C) / max(albedo, floor),
// the path tracer's mean radiance less the obscurance frame's, divided by the albedo so that the
// filter never blurs a texture (the denoiser's demodulation). Pixels without a hit and pixels that
// see an emitter keep the obscurance frame (w = 0): both methods estimate the seen emission the
// same way, and its edges are no surface to filter along.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/accumulate.glsl"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { CorrectionPush pc; };
layout(std430, binding = kBindingCorrectionParams) readonly buffer Params { DenoiseParams params; };
layout(std430, binding = kBindingResidualComposed) readonly buffer Composed { vec4 composed[]; };
layout(std430, binding = kBindingResidualAovs) readonly buffer Aovs { vec4 aov[]; };
layout(std430, binding = kBindingResidualSampleCounts) readonly buffer SampleCounts { uint sampleCounts[]; };
layout(std430, binding = kBindingResidualPaths) readonly buffer Paths { vec4 paths[]; };
layout(std430, binding = kBindingResidualGuide) writeonly buffer GuideOut { uvec4 guide[]; };
layout(std430, binding = kBindingResidualBase) writeonly buffer BaseOut { vec4 base[]; };
layout(std430, binding = kBindingResidualOut) writeonly buffer ResidualOut { vec4 residual[]; };

void main() {
  const uint local = gl_GlobalInvocationID.x;
  const uint width = params.frame.x, slots = pc.composedSlots;
  if (local >= width * pc.rows) return;
  const uint pixel = pc.firstRow * width + local;
  const float inv = 1.0 / float(max(sampleCounts[local], 1u));
  const vec4 albedo = OBS_SUM(aov, local * kAovSlots + kAovAlbedo) * inv; // rgb, a = coverage
  const vec4 normalDepth = OBS_SUM(aov, local * kAovSlots + kAovNormal) * inv;
  const uint material = floatBitsToUint(OBS_SUM(aov, local * kAovSlots + kAovIds).y);

  const Guide g = pixelGuide(albedo, normalDepth, material);
  const uvec4 packed = encodeGuide(g);
  guide[pixel] = packed;

  const uint o = local * slots;
  const vec3 c = composed[o + kComposeCombined].rgb;
  base[pixel] = vec4(c, 0.0);
  const vec3 path = OBS_SUM(paths, pixel).rgb / float(max(pc.pathSamples, 1u));
  const bool seesEmission = any(greaterThan(composed[o + kComposeEmission].rgb, vec3(0.0)));
  if (!guideHit(g) || seesEmission) {
    residual[pixel] = vec4(0.0);
    return;
  }
  // Divided by the albedo as the filter's last step multiplies it back (the guide's halves), so an
  // unfiltered residual comes back as it went in.
  residual[pixel] = vec4((path - c) / demodulationAlbedo(decodeGuide(packed)), 1.0);
}
