#version 460
// trace.comp — traces a buffer of rays (closest hit or any hit), one per invocation. Used by
// `obscura bench-rays` and by the traversal tests, so the benchmark measures the code tested.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { TracePush pc; };
layout(std430, set = 0, binding = kBindingPassFirst) readonly buffer Rays { GpuRay rays[]; };
layout(std430, set = 0, binding = kBindingPassFirst + 1) writeonly buffer Hits { GpuHit hits[]; };
layout(std430, set = 0, binding = kBindingPassFirst + 2) writeonly buffer Steps { uint steps[]; };

void main() {
  uint i = gl_GlobalInvocationID.x + pc.params.w;
  if (i >= pc.params.x) return;
  GpuRay ray = rays[i];
  bool anyHit = pc.params.y != 0u;
  RayHit h = traverseBvh(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, anyHit,
                         kMaxTraversalSteps);
  if (h.primitive == kTruncatedHit) atomicAdd(status[kStatusTruncated], 1u);
  GpuHit out_;
  out_.t = h.t;
  out_.u = h.u;
  out_.v = h.v;
  out_.primitive = h.primitive;
  hits[i] = out_;
  if (pc.params.z != 0u) steps[i] = h.steps;
}
