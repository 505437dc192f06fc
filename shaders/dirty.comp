#version 460
// dirty.comp — marks the pixels of a band that a geometry edit can change (host_device.h,
// "dirty.comp"): covered by a changed box on screen, hit points within dMax of one, segments to a
// light near one, or a specular path that left the scene. Conservative: every test bounds with
// spheres (a glossy pixel's box holds its path vertices, so its segments too), so a pixel it leaves
// clean cannot change (FrameEdits.* check the result against a full render bit for bit).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"

layout(local_size_x = kWorkgroupSize1D) in;
layout(std430, binding = kBindingDirtyParams) readonly buffer Params { DirtyPush pc; };
layout(std430, binding = kBindingDirtyHitBounds) readonly buffer HitBounds { vec4 hitBounds[]; };
layout(std430, binding = kBindingDirtyLights) readonly buffer LightBounds { vec4 lightBounds[]; };
layout(std430, binding = kBindingDirtyMask) writeonly buffer Mask { uint dirty[]; };
layout(std430, binding = kBindingDirtyStatus) buffer Status { uint status[]; };

// Distance from point q to the segment [a, b] (or the ray from a along b - a when infinite).
float segmentDistance(vec3 q, vec3 a, vec3 b, bool infinite) {
  vec3 ab = b - a;
  float len2 = dot(ab, ab);
  float t = len2 > 0.0 ? dot(q - a, ab) / len2 : 0.0;
  t = infinite ? max(t, 0.0) : clamp(t, 0.0, 1.0);
  return distance(q, a + t * ab);
}

bool touched(uint pixel, uvec2 framePixel) {
  if (pc.params.y != 0.0) return true;
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (pc.spheres[b].w < 0.0) continue;
    uvec4 r = pc.rects[b];
    if (framePixel.x >= r.x && framePixel.x <= r.z && framePixel.y >= r.y && framePixel.y <= r.w) return true;
  }
  vec4 lo = hitBounds[2u * pixel], hi = hitBounds[2u * pixel + 1u];
  if (hi.w == 0.0) return false; // no sample hit anything: only its camera rays could change
  if (lo.w != 0.0) return true;  // a specular path left the scene: it may pass anywhere
  vec3 centre = 0.5 * (lo.xyz + hi.xyz);
  float radius = 0.5 * distance(lo.xyz, hi.xyz);
  const float dMax = pc.params.x;
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    vec4 sphere = pc.spheres[b];
    if (sphere.w < 0.0) continue;
    // Obscurance rays reach dMax from a hit point.
    if (distance(centre, sphere.xyz) <= radius + sphere.w + dMax) return true;
    // Shadow rays run from a hit point to a point of a light: within (hit radius + light radius)
    // of the segment between the two spheres' centres.
    for (uint s = 0u; s < pc.frame.w; ++s) {
      if (s == floatBitsToUint(pc.params.z)) continue; // a new light, traced at every pixel
      vec4 light = lightBounds[2u * s], direction = lightBounds[2u * s + 1u];
      bool infinite = direction.w != 0.0;
      vec3 far = infinite ? centre - direction.xyz : light.xyz;
      if (segmentDistance(sphere.xyz, centre, far, infinite) <= sphere.w + radius + light.w) return true;
    }
  }
  return false;
}

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint width = pc.frame.x;
  if (pixel >= width * pc.frame.y) return;
  bool d = touched(pixel, uvec2(pixel % width, pixel / width + pc.frame.z));
  dirty[pixel] = d ? 1u : 0u;
  if (d) atomicAdd(status[kStatusDirtyPixels], 1u);
}
