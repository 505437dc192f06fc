#version 460
// denoise_temporal.comp — the current n-sample mean c blended with the reprojected history (h
// samples) by their sample counts, (n c + h carry) / (n + h) (Schied et al. 2017, §4.2, with the
// renderer's own progressive mean in place of their exponential average: while the camera stays,
// the renderer accumulates and the carry stays fixed), and each term's luminance variance.
//
// The variance: the renderer hands over means, not samples, so the temporal second moments of
// Schied et al. are not there; the variance of c is read from its neighbours on the same surface
// (their §4.2 fallback for short histories), as the smallest of the four 3x3 windows that have the
// pixel in a corner (OURS: after Kuwahara's filter, "Processing of RI-angiocardiographic images",
// 1976). A window lying across a shadow boundary measures the step, not the noise; at a straight
// edge one window lies on the pixel's side, so the edge keeps the strict luminance weight that
// keeps it sharp. The history lowers it as it lowers the noise: Var = Var(c) n / (n + h).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(std430, binding = kBindingDenoiseParams) readonly buffer Params { DenoiseParams params; };
layout(binding = kBindingTemporalGuide) uniform usamplerBuffer guide;
layout(binding = kBindingTemporalNoisy) uniform usamplerBuffer noisy;
layout(std430, binding = kBindingTemporalCarry) readonly buffer Carry { uvec4 carry[]; };
layout(std430, binding = kBindingTemporalOut) writeonly buffer Out { uvec4 integrated[]; };

// A neighbour up to 2 pixels away on the pixel's plane lies within about that many pixel widths of it.
const float kVariancePlanePixels = 2.0;
// A window needs this many of its 9 pixels on the pixel's surface to measure a variance.
const float kMinWindowPixels = 4.0;

void main() {
  const uvec2 size = params.frame.xy;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(size.x) || p.y >= int(size.y)) return;
  const bool specular = params.frame.w != 0u;
  const uint pixel = uint(p.y) * size.x + uint(p.x);
  const Guide g = decodeGuide(texelFetch(guide, int(pixel)));
  const Illum c = readIllum(noisy, pixel, true);
  const Illum k = decodeIllum(carry[2u * pixel], carry[2u * pixel + 1u]);
  const float n = c.samples, h = guideHit(g) ? k.samples : 0.0, total = max(n + h, 1.0);

  Illum o = noIllum();
  o.direct = (n * c.direct + h * k.direct) / total;
  o.ambient = (n * c.ambient + h * k.ambient) / total;
  o.specular = (n * c.specular + h * k.specular) / total;
  o.samples = n + h;
  if (guideHit(g)) {
    const vec3 x = pixelPoint(params.camera, p, size, g.depth);
    const float tolerance = kVariancePlanePixels * pixelFootprint(params.camera, g.depth, size);
    // Per window (0: +x +y, 1: -x +y, 2: +x -y, 3: -x -y): pixels, and per term the sums of
    // luminance and of its square.
    vec4 count = vec4(0.0);
    vec4 sum[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
    vec4 sum2[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const ivec2 q = p + ivec2(dx, dy);
        if (q.x < 0 || q.y < 0 || q.x >= int(size.x) || q.y >= int(size.y)) continue;
        const uint i = uint(q.y) * size.x + uint(q.x);
        const Guide gq = decodeGuide(texelFetch(guide, int(i)));
        if (!sameSurface(g, x, gq, pixelPoint(params.camera, q, size, gq.depth), tolerance)) continue;
        const Illum s = readIllum(noisy, i, specular);
        const vec3 l = vec3(luminance(s.direct), luminance(s.ambient), luminance(s.specular));
        // The axes belong to two windows, the centre to all four.
        const vec4 in_ = vec4(dx >= 0 && dy >= 0, dx <= 0 && dy >= 0, dx >= 0 && dy <= 0, dx <= 0 && dy <= 0);
        count += in_;
        for (int t = 0; t < 3; ++t) {
          sum[t] += in_ * l[t];
          sum2[t] += in_ * l[t] * l[t];
        }
      }
    }
    // Sample variances (Bessel's correction) of the windows on the pixel's surface.
    vec3 smallest = vec3(1e30);
    for (int w = 0; w < 4; ++w) {
      if (count[w] < kMinWindowPixels) continue;
      const float m = count[w];
      for (int t = 0; t < 3; ++t)
        smallest[t] = min(smallest[t], max(sum2[t][w] - sum[t][w] * sum[t][w] / m, 0.0) / (m - 1.0));
    }
    // No window on the pixel's surface (a sliver): nothing to compare with, nothing to filter with.
    if (smallest.x > 1e29) smallest = vec3(0.0);
    o.variance = smallest * (n / total);
  }
  OBS_WRITE_ILLUM(integrated, pixel, o)
}
