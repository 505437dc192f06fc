#version 460
// dirty.comp — marks the pixels of a band that a geometry edit can change (host_device.h,
// "dirty.comp"): covered by a changed box on screen, a hit box within dMax of one, a shaft from the
// hit box to a light that meets one, or a specular path that left the scene. Conservative: every
// test bounds what rays can reach with boxes and convex hulls, so a pixel it leaves clean cannot
// change (GeometryEdit.* check the result against a full render bit for bit).
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"

layout(local_size_x = kWorkgroupSize1D) in;
layout(std430, binding = kBindingDirtyParams) readonly buffer Params { DirtyPush pc; };
layout(std430, binding = kBindingDirtyHitBounds) readonly buffer HitBounds { vec4 hitBounds[]; };
layout(std430, binding = kBindingDirtyLights) readonly buffer LightBounds { vec4 lightBounds[]; };
layout(std430, binding = kBindingDirtyMask) buffer Mask { uint dirty[]; }; // mask, then list
layout(std430, binding = kBindingDirtyStatus) buffer Status { uint status[]; };

// The interval a box (centre c, half extent h) projects to on axis n.
vec2 project(vec3 c, vec3 h, vec3 n) {
  float m = dot(c, n), r = dot(h, abs(n));
  return vec2(m - r, m + r);
}

bool apart(vec2 a, vec2 b) { return a.y < b.x || b.y < a.x; }

// Whether box B can meet a segment from box A to box L. Every such segment lies in the convex hull
// of A and L (the paper's shaft, Haines & Wallace 1994), whose projection on any axis is the hull
// of A's and L's projections; B misses the hull when its projection misses that on some axis. The
// axes: x, y, z and three across the shaft's direction, which make a long shaft thin.
bool meetsShaft(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 lc, vec3 lh) {
  vec3 d = lc - ac;
  vec3 axes[6] = vec3[6](vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1), vec3(0.0, -d.z, d.y), vec3(d.z, 0.0, -d.x),
                         vec3(-d.y, d.x, 0.0));
  for (uint i = 0u; i < 6u; ++i) {
    vec3 n = axes[i];
    if (dot(n, n) == 0.0) continue;
    vec2 a = project(ac, ah, n), l = project(lc, lh, n);
    if (apart(project(bc, bh, n), vec2(min(a.x, l.x), max(a.y, l.y)))) return false;
  }
  return true;
}

// The same for a directional light: box A swept to infinity along -direction. Across the direction
// the sweep projects as A does; along it, it reaches from A's far end towards the light.
bool meetsInfiniteShaft(vec3 bc, vec3 bh, vec3 ac, vec3 ah, vec3 direction) {
  vec3 d = -direction;
  vec3 axes[3] = vec3[3](vec3(0.0, -d.z, d.y), vec3(d.z, 0.0, -d.x), vec3(-d.y, d.x, 0.0));
  for (uint i = 0u; i < 3u; ++i)
    if (dot(axes[i], axes[i]) > 0.0 && apart(project(bc, bh, axes[i]), project(ac, ah, axes[i]))) return false;
  vec2 a = project(ac, ah, d);
  return project(bc, bh, d).y >= a.x;
}

bool touched(uint pixel, uvec2 framePixel) {
  if (pc.params.y != 0.0) return true;
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (pc.boxLo[b].w == 0.0) continue;
    uvec4 r = pc.rects[b];
    if (framePixel.x >= r.x && framePixel.x <= r.z && framePixel.y >= r.y && framePixel.y <= r.w) return true;
  }
  vec4 lo = hitBounds[2u * pixel], hi = hitBounds[2u * pixel + 1u];
  if (hi.w == 0.0) return false; // no sample hit anything: only its camera rays could change
  if (lo.w != 0.0) return true;  // a specular path left the scene: it may pass anywhere
  vec3 ac = 0.5 * (lo.xyz + hi.xyz), ah = 0.5 * (hi.xyz - lo.xyz);
  const float dMax = pc.params.x;
  const uint traced = floatBitsToUint(pc.params.z);
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (pc.boxLo[b].w == 0.0) continue;
    vec3 blo = pc.boxLo[b].xyz, bhi = pc.boxHi[b].xyz;
    // Obscurance rays reach dMax from a hit point: the distance between the two boxes.
    if (length(max(vec3(0.0), max(lo.xyz - bhi, blo - hi.xyz))) <= dMax) return true;
    vec3 bc = 0.5 * (blo + bhi), bh = 0.5 * (bhi - blo);
    // Shadow rays run from a hit point to a point of a light.
    for (uint s = 0u; s < pc.frame.w; ++s) {
      if (s == traced) continue; // a new light, traced at every pixel
      vec4 light = lightBounds[2u * s], extent = lightBounds[2u * s + 1u];
      bool meets = light.w != 0.0 ? meetsInfiniteShaft(bc, bh, ac, ah, extent.xyz)
                                  : meetsShaft(bc, bh, ac, ah, light.xyz, extent.xyz);
      if (meets) return true;
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
  if (!d) return;
  atomicAdd(status[kStatusDirtyPixels], 1u);
  // The list the retrace dispatches over (the host reset its header to (0, 1, 1, 0)); lanes append
  // in order, so neighbours stay neighbours.
  const uint base = dirtyListBase(width * pc.frame.y);
  uint slot = atomicAdd(dirty[base + kQueueCount], 1u);
  dirty[base + kQueueHeader + slot] = pixel;
  atomicMax(dirty[base + kQueueGroupsX], slot / kWorkgroupSize1D + 1u);
}
