#version 460
// denoise_reproject.comp — the history (the previous frame's temporally integrated terms, made
// with the previous camera) seen from the current camera (Schied et al. 2017, §4.2): each pixel's
// point, at its depth along its centre ray, is projected into the previous image and the four
// history pixels around it are blended bilinearly, each kept only if it lies on the same surface
// (same material, normals within ~25 degrees, off the pixel's plane by less than
// kReprojectPlanePixels of the history's pixel width). Where none is kept the pixel was not seen
// before (a disocclusion, or off-screen): its carry counts for no sample.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/denoise.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(std430, binding = kBindingDenoiseParams) readonly buffer Params { DenoiseParams params; };
layout(binding = kBindingReprojectGuide) uniform usamplerBuffer guide;
layout(binding = kBindingReprojectHistoryGuide) uniform usamplerBuffer historyGuide;
layout(binding = kBindingReprojectHistory) uniform usamplerBuffer history;
layout(std430, binding = kBindingReprojectCarry) writeonly buffer Carry { uvec4 carry[]; };

// A history pixel on the same plane lies within about a pixel of the projected point; two
// pixels' width allows for the mean depth of a pixel whose samples spread over a slanted surface.
const float kReprojectPlanePixels = 2.0;
// Below this much bilinear weight of kept pixels, the history is too thin to trust.
const float kMinKeptWeight = 0.05;

void main() {
  const uvec2 size = params.frame.xy;
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(size.x) || p.y >= int(size.y)) return;
  const uint pixel = uint(p.y) * size.x + uint(p.x);
  const Guide g = decodeGuide(texelFetch(guide, int(pixel)));

  Illum sum = noIllum();
  float kept = 0.0;
  vec2 image;
  const vec3 x = pixelPoint(params.camera, p, size, g.depth);
  if (guideHit(g) && projectToImage(params.previous, x, size, image)) {
    const float tolerance = kReprojectPlanePixels * pixelFootprint(params.previous, distance(x, params.previous.origin.xyz), size);
    const vec2 f = image - 0.5; // pixel centres lie at integer + 0.5
    const ivec2 base = ivec2(floor(f));
    const vec2 t = f - vec2(base);
    for (int k = 0; k < 4; ++k) {
      const ivec2 q = base + ivec2(k & 1, k >> 1);
      if (q.x < 0 || q.y < 0 || q.x >= int(size.x) || q.y >= int(size.y)) continue;
      const uint i = uint(q.y) * size.x + uint(q.x);
      const Guide h = decodeGuide(texelFetch(historyGuide, int(i)));
      if (!sameSurface(g, x, h, pixelPoint(params.previous, q, size, h.depth), tolerance)) continue;
      const float w = ((k & 1) != 0 ? t.x : 1.0 - t.x) * ((k >> 1) != 0 ? t.y : 1.0 - t.y);
      const Illum s = readIllum(history, i, true);
      sum.direct += w * s.direct;
      sum.ambient += w * s.ambient;
      sum.specular += w * s.specular;
      sum.samples += w * s.samples;
      kept += w;
    }
  }
  Illum c = noIllum();
  if (kept >= kMinKeptWeight) {
    c.direct = sum.direct / kept;
    c.ambient = sum.ambient / kept;
    c.specular = sum.specular / kept;
    c.samples = min(sum.samples / kept, float(params.frame.z));
  }
  OBS_WRITE_ILLUM(carry, pixel, c)
}
