#version 460
// correction_filter.comp — one a-trous step of the path-traced correction's residual (Dammertz et
// al., "Edge-Avoiding A-Trous Wavelet Transform for fast Global Illumination Filtering", HPG
// 2010): a 5x5 B3-spline kernel with taps `step` pixels apart, each weighted by geometry alone,
//   w = [same material] max(0, n_p . n_q)^128 exp(-|n_p . (x_q - x_p)| / (sigma_z |p - q| s_p)),
// the denoiser's normal and plane stops (denoise_atrous.comp). No luminance stop: the residual is
// the ambient model's smooth error plus the paths' noise, and a stop on its value would keep the
// noise. The last step also writes the corrected image, max(base + residual x albedo, 0); step 0 takes
// each residual as it is (enough paths that no filter is wanted).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(push_constant) uniform Push { CorrectionPush pc; };
layout(std430, binding = kBindingCorrectionParams) readonly buffer Params { DenoiseParams params; };
layout(std430, binding = kBindingCorrectionGuide) readonly buffer GuideIn { uvec4 guide[]; };
layout(std430, binding = kBindingCorrectionBase) readonly buffer BaseIn { vec4 base[]; };
layout(std430, binding = kBindingCorrectionIn) readonly buffer ResidualIn { vec4 source[]; };
layout(std430, binding = kBindingCorrectionOut) writeonly buffer ResidualOut { vec4 filtered[]; };
layout(std430, binding = kBindingCorrectionImage) writeonly buffer ImageOut { vec4 corrected[]; };

void main() {
  const uvec2 size = params.frame.xy;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(size.x) || p.y >= int(size.y)) return;
  const uint pixel = uint(p.y) * size.x + uint(p.x);
  const vec4 c = source[pixel];
  const Guide g = decodeGuide(guide[pixel]);
  vec3 r = c.rgb;
  if (c.w > 0.0 && pc.step > 0u) {
    const int step = int(pc.step);
    const vec3 x = pixelPoint(params.camera, p, size, g.depth);
    const float planeScale = params.weights.x * pixelFootprint(params.camera, g.depth, size) * float(step);
    const float kernel[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0); // B3 spline, |offset| 0, 1, 2
    float weight = kernel[0] * kernel[0];
    vec3 sum = weight * c.rgb;
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const ivec2 q = p + ivec2(dx, dy) * step;
        if ((dx == 0 && dy == 0) || q.x < 0 || q.y < 0 || q.x >= int(size.x) || q.y >= int(size.y)) continue;
        const uint i = uint(q.y) * size.x + uint(q.x);
        const vec4 s = source[i];
        if (s.w == 0.0) continue; // kept pixels give nothing
        const Guide h = decodeGuide(guide[i]);
        if (h.material != g.material) continue;
        const float w = kernel[abs(dx)] * kernel[abs(dy)] * normalWeight(dot(g.normal, h.normal)) *
                        exp(-planeDistance(x, g.normal, pixelPoint(params.camera, q, size, h.depth),
                                           planeScale * length(vec2(dx, dy))));
        sum += w * s.rgb;
        weight += w;
      }
    }
    r = sum / weight;
  }
  filtered[pixel] = vec4(r, c.w);
  // A filtered residual can ask for less than no light where the frame is dark: none is the least.
  if (pc.lastStep != 0u)
    corrected[pixel] = vec4(max(base[pixel].rgb + (c.w > 0.0 ? r * demodulationAlbedo(g) : vec3(0.0)), vec3(0.0)), 1.0);
}
