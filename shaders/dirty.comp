#version 460
// dirty.comp — marks the pixels of a band that a geometry edit can change (host_device.h,
// "dirty.comp"): covered by a changed box on screen, a hit box within dMax of one, a shaft from the
// hit box to a light that meets one, or a specular path that left the scene. Conservative: every
// test bounds what rays can reach with boxes and convex hulls, so a pixel it leaves clean cannot
// change (GeometryEdit.* check the result against a full render bit for bit).
//
// With probing (probing = 1) it runs twice (DirtyStagePush): kDirtyStageMark marks the pixels a
// changed box covers on screen certain (2) and those only a bound flags candidates (1), and lists
// the candidates; the probing passes (lib/probe.glsl) replay the candidates' rays and mark 2 those
// one of whose rays meets a changed box; kDirtyStageList then keeps the 2s (as 1) and lists them.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/shaft.glsl"
#include "lib/queue_append.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(std430, binding = kBindingDirtyParams) readonly buffer Params { DirtyPush pc; };
layout(std430, binding = kBindingDirtyHitBounds) readonly buffer HitBounds { vec4 hitBounds[]; };
layout(std430, binding = kBindingDirtyLights) readonly buffer LightBounds { vec4 lightBounds[]; };
layout(std430, binding = kBindingDirtyMask) buffer Mask { uint dirty[]; }; // mask, then list
layout(std430, binding = kBindingDirtyStatus) buffer Status { uint status[]; };
layout(push_constant) uniform Stage { DirtyStagePush stage; };

// Whether a ray of the pixel off the changed boxes' screen rectangles may meet one of them.
bool maybeTouched(uint pixel) {
  vec4 lo = hitBounds[2u * pixel], hi = hitBounds[2u * pixel + 1u];
  if (hi.w == 0.0) return false; // no sample hit anything: only its camera rays could change
  if (lo.w != 0.0) return true;  // a specular path left the scene, or an obscurance ray was traced
                                 // past dMax (kFlagDarkEscapes): it may pass anywhere
  vec3 ac = 0.5 * (lo.xyz + hi.xyz), ah = 0.5 * (hi.xyz - lo.xyz);
  const float dMax = pc.dMax;
  const uint traced = pc.tracedLight;
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (pc.boxLo[b].w == 0.0) continue;
    vec3 blo = pc.boxLo[b].xyz, bhi = pc.boxHi[b].xyz;
    // Obscurance rays reach dMax from a hit point: the distance between the two boxes.
    if (length(max(vec3(0.0), max(lo.xyz - bhi, blo - hi.xyz))) <= dMax) return true;
    vec3 bc = 0.5 * (blo + bhi), bh = 0.5 * (bhi - blo);
    // Shadow rays run from a hit point to a point of a light.
    for (uint s = 0u; s < pc.lightCount; ++s) {
      if (s == traced) continue; // a new light, traced at every pixel
      vec4 light = lightBounds[2u * s], extent = lightBounds[2u * s + 1u];
      bool meets = light.w != 0.0 ? meetsInfiniteShaft(bc, bh, ac, ah, extent.xyz)
                                  : meetsShaft(bc, bh, ac, ah, light.xyz, extent.xyz);
      if (meets) return true;
    }
  }
  return false;
}

// 2: a changed box covers the pixel on screen (or every pixel is dirty); 1: a bound says one of
// its rays may meet a changed box; 0: none can.
uint touched(uint pixel, uvec2 framePixel) {
  if (pc.all != 0u) return kDirtyCertain;
  for (uint b = 0u; b < kMaxChangedBoxes; ++b) {
    if (pc.boxLo[b].w == 0.0) continue;
    uvec4 r = pc.rects[b];
    if (framePixel.x >= r.x && framePixel.x <= r.z && framePixel.y >= r.y && framePixel.y <= r.w) return kDirtyCertain;
  }
  return maybeTouched(pixel) ? 1u : 0u;
}

// Appends `pixel` to the band's list (lib/queue_append.glsl: one atomic per SIMD group), and with
// `counted` counts it in the status (one atomic per group too).
void list(uint pixel, bool counted) {
  OBS_QUEUE_APPEND(dirty, dirtyListBase(pc.width * pc.rows), pixel)
  if (counted) {
    const uint listed = subgroupBallotBitCount(subgroupBallot(true));
    if (subgroupElect()) atomicAdd(status[kStatusDirtyPixels], listed);
  }
}

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  uint width = pc.width;
  if (pixel >= width * pc.rows) return;
  const bool probing = pc.probing != 0u;
  if (stage.stage == kDirtyStageList) { // after the probes: what they (or the screen) made certain
    bool d = dirty[pixel] == kDirtyCertain;
    dirty[pixel] = d ? 1u : 0u;
    if (d) list(pixel, true);
    return;
  }
  uint t = touched(pixel, uvec2(pixel % width, pixel / width + pc.firstRow));
  if (!probing) t = min(t, 1u);
  dirty[pixel] = t;
  if (!probing && t != 0u) atomicAdd(status[kStatusDirtyPixels], 1u);
  if (t == 1u) list(pixel, false); // without probing: every dirty pixel; with it: the candidates
}
