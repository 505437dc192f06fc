#version 460
// Counts the passes of one loop of `params.x` iterations: on lavapipe the loop limiter stops it
// at 65,535 without a word. The test documents that the limiter exists on this driver, which is
// why traversal counts its own steps (shared/host_device.h kMaxTraversalSteps).
layout(local_size_x = 8) in;
layout(push_constant) uniform Push { uvec4 params; };
layout(std430, binding = 0) writeonly buffer Counts { uint counts[]; };

void main() {
  uint n = 0u;
  for (uint i = 0u; i < params.x; ++i) n++;
  counts[gl_GlobalInvocationID.x] = n;
}
