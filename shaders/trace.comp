#version 460
// trace.comp — traces a buffer of rays (closest hit or any hit), kRaysPerLane per invocation
// through one refilling traversal loop (lib/bvh_stream.glsl, the wide or the binary layout's):
// 64 on lavapipe, 8 on a GPU (a specialisation constant, as is the workgroup size;
// host/bench/ray_tracer.h); kRaysPerLane = 1 goes straight through traverseBvh. Used by `obscura bench-rays` and by the traversal tests, so
// the benchmark measures the code tested.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/intersect.glsl"
#define OBS_BVH_ITEMS_STORAGE_BINDING (kBindingPassFirst + 3) // --bvh-items storage
#include "lib/bvh.glsl"

layout(local_size_x = kTraceWorkgroupSize, local_size_x_id = kSpecConstantTraceWorkgroupSize) in;
layout(push_constant) uniform Push { TracePush pc; };
layout(constant_id = kSpecConstantTraceSteps) const bool kRecordSteps = false;
layout(constant_id = kSpecConstantTraceRaysPerLane) const uint kRaysPerLane = kTraceRaysPerLane;
// Texel views (host/bench/ray_tracer.cpp), which lavapipe reads and writes a texel per lane at a
// time: ray i = texels 2i (origin, tmin) and 2i + 1 (direction, tmax); hit i = one texel
// (t, u, v, primitive bits); steps i = one texel.
layout(set = 0, binding = kBindingPassFirst) uniform samplerBuffer rays;
layout(set = 0, binding = kBindingPassFirst + 1, rgba32f) uniform writeonly imageBuffer hits;
layout(set = 0, binding = kBindingPassFirst + 2, r32ui) uniform writeonly uimageBuffer steps;

// Ray k of this invocation: 8 neighbouring invocations take 8 neighbouring rays at a time, so
// rays that arrive in a coherent order are traced side by side.
uint rayIndex(uint k) {
  uint g = gl_GlobalInvocationID.x;
  return pc.firstRay + (g / 8u) * 8u * kRaysPerLane + k * 8u + g % 8u;
}

GpuRay streamRay(uint k) {
  int i = int(rayIndex(k));
  return GpuRay(texelFetch(rays, 2 * i), texelFetch(rays, 2 * i + 1));
}

// The hits wait in shared memory (plain memory on lavapipe) until the loop is done, and only as
// t and the triangle's texel: a texel store inside the loop costs every pass a loop over the
// lanes (Sponza 1.2x slower), and the barycentrics are found again afterwards (storedHit),
// which leaves their two divisions out of the loop.
shared uvec2 sHits[gl_WorkGroupSize.x * kRaysPerLane];
shared uint sSteps[gl_WorkGroupSize.x * kRaysPerLane];

uint hitSlot(uint k) { return gl_LocalInvocationID.x * kRaysPerLane + k; }

void streamHit(uint k, RayHit h) {
  sHits[hitSlot(k)] = uvec2(floatBitsToUint(h.t), h.primitive == kTruncatedHit ? kTruncatedHit : h.item);
  if (kRecordSteps) sSteps[hitSlot(k)] = h.steps;
}

#include "lib/bvh_stream.glsl"

void main() {
  if (kRaysPerLane == 1u) { // one ray per invocation: straight through traverseBvh
    const uint i = rayIndex(0u);
    if (i >= pc.rayCount) return;
    GpuRay ray = streamRay(0u);
    RayHit h = traverseBvh(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, pc.anyHit != 0u,
                           kMaxTraversalSteps);
    if (h.primitive == kTruncatedHit) atomicAdd(status[kStatusTruncated], 1u);
    imageStore(hits, int(i), vec4(h.t, h.u, h.v, uintBitsToFloat(h.primitive)));
    if (kRecordSteps) imageStore(steps, int(i), uvec4(h.steps));
    return;
  }
  uint count = 0u;
  while (count < kRaysPerLane && rayIndex(count) < pc.rayCount) ++count;
  // An if, not ?: — glslang evaluates both sides of a ?: whose condition is a specialisation
  // constant (then selects), which ran both loops over one layout.
  uint truncated;
  if (kBinaryLayout) truncated = traverseBinaryStream(count, pc.anyHit != 0u, kMaxTraversalSteps);
  else truncated = traverseStream(count, pc.anyHit != 0u, kMaxTraversalSteps);
  if (truncated != 0u) atomicAdd(status[kStatusTruncated], truncated);
  for (uint k = 0u; k < count; ++k) {
    uvec2 stored = sHits[hitSlot(k)];
    GpuRay ray = streamRay(k);
    RayHit h = storedHit(ray.origin.xyz, ray.direction.xyz, ray.origin.w, uintBitsToFloat(stored.x), stored.y);
    imageStore(hits, int(rayIndex(k)), vec4(h.t, h.u, h.v, uintBitsToFloat(h.primitive)));
    if (kRecordSteps) imageStore(steps, int(rayIndex(k)), uvec4(sSteps[hitSlot(k)]));
  }
}
