#version 460
// denoise_atrous.comp — one iteration of the edge-avoiding a-trous wavelet filter (Dammertz et al.,
// "Edge-Avoiding A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG 2010) as
// SVGF steers it (Schied et al. 2017, §4.3, eqs. 1-5): a 5x5 B3-spline kernel whose taps lie
// `step` pixels apart (1, 2, 4, ... over the iterations), each tap weighted by
//   w_n = max(0, n_p . n_q)^128                              normals (their sigma_n)
//   w_z = exp(-|n_p . (x_q - x_p)| / (sigma_z |p - q| s_p))   OURS: the distance off p's plane in
//         units of the taps' distance (s_p: a pixel's width at p), where SVGF compares depths along
//         the screen-space depth gradient; the same on slanted surfaces, no derivative needed
//   w_a = exp(-max_c |a_p - a_q| / sigma_a)                   albedo (material boundaries)
//   w_l = exp(-|l_p - l_q| / (sigma_l sqrt(Var(l_p)) + eps)) luminance, per term (eq. 5)
// applied to the demodulated direct and ambient terms and the specular light separately; the
// variances are filtered with the squared weights (eq. 2), so each iteration's luminance weight
// sees the noise left.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(push_constant) uniform Push { DenoisePush pc; };
layout(std430, binding = kBindingDenoiseParams) readonly buffer Params { DenoiseParams params; };
layout(binding = kBindingAtrousGuide) uniform usamplerBuffer guide;
layout(binding = kBindingAtrousIn) uniform usamplerBuffer source;
layout(std430, binding = kBindingAtrousOut) writeonly buffer Out { uvec4 filtered[]; };

// eps of w_l: a relative difference of half precision (2^-11) is no edge.
const float kLuminanceFloor = 1e-3;

void main() {
  const uvec2 size = params.frame.xy;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(size.x) || p.y >= int(size.y)) return;
  const bool specular = params.frame.w != 0u;
  const uint pixel = uint(p.y) * size.x + uint(p.x);
  const Illum c = readIllum(source, pixel, true);
  const Guide g = decodeGuide(texelFetch(guide, int(pixel)));
  if (!guideHit(g)) {
    OBS_WRITE_ILLUM(filtered, pixel, c)
    return;
  }
  const int step = int(pc.step);
  const float sigmaZ = params.weights.x, sigmaA = params.weights.y, sigmaL = params.weights.z;
  const vec3 x = pixelPoint(params.camera, p, size, g.depth);
  const float planeScale = sigmaZ * pixelFootprint(params.camera, g.depth, size) * float(step);
  const vec3 l = vec3(luminance(c.direct), luminance(c.ambient), luminance(c.specular));
  const vec3 stop = sigmaL * sqrt(c.variance) + kLuminanceFloor * (l + 1e-3);

  const float kernel[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0); // B3 spline, |offset| 0, 1, 2
  vec3 weight = vec3(kernel[0] * kernel[0]);
  vec3 sumD = weight.x * c.direct, sumA = weight.y * c.ambient, sumS = weight.z * c.specular;
  vec3 sumVar = weight * weight * c.variance;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const ivec2 q = p + ivec2(dx, dy) * step;
      if ((dx == 0 && dy == 0) || q.x < 0 || q.y < 0 || q.x >= int(size.x) || q.y >= int(size.y)) continue;
      const uint i = uint(q.y) * size.x + uint(q.x);
      const Guide h = decodeGuide(texelFetch(guide, int(i)));
      if (!guideHit(h)) continue;
      const Illum s = readIllum(source, i, specular);
      const vec3 da = abs(g.albedo - h.albedo);
      // The geometric stops in one exponent: w_z w_a.
      const float geometric = planeDistance(x, g.normal, pixelPoint(params.camera, q, size, h.depth),
                                            planeScale * length(vec2(dx, dy))) +
                              max(da.r, max(da.g, da.b)) / sigmaA;
      const vec3 ls = vec3(luminance(s.direct), luminance(s.ambient), luminance(s.specular));
      const vec3 w = kernel[abs(dx)] * kernel[abs(dy)] * normalWeight(dot(g.normal, h.normal)) *
                     exp(-(geometric + abs(l - ls) / stop));
      sumD += w.x * s.direct;
      sumA += w.y * s.ambient;
      sumS += w.z * s.specular;
      sumVar += w * w * s.variance;
      weight += w;
    }
  }
  Illum o = c;
  o.direct = sumD / weight.x;
  o.ambient = sumA / weight.y;
  o.specular = sumS / weight.z;
  o.variance = sumVar / (weight * weight);
  OBS_WRITE_ILLUM(filtered, pixel, o)
}
