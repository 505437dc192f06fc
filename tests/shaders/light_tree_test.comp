#version 460
// Runs the production lights.glsl selection (the light tree beyond kMaxSpatialLights lights, the
// flat weights up to it) so tests/render/light_tree_test.cpp can compare it with the C++ twins
// (render/scene_data/light_selection.h) and check its distribution.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/sampling.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { uvec4 params; }; // x = case count, y = light count

// p.xyz = shading point, p.w = u (the selection number); n.xyz = normal, n.w = a light (uint
// bits) whose selection pdf is asked.
struct TreeCase { vec4 p; vec4 n; };
layout(std430, binding = 0) readonly buffer Cases { TreeCase cases[]; };
// x = the light selectLight chose (uint bits), y = its selection probability, z = the asked
// light's lightSelectionPdf, w = lightSelectionPdf of the chosen light.
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
layout(std430, binding = 2) readonly buffer LightBuffer { GpuLight lights[]; };
layout(std430, binding = 3) readonly buffer EmitterBuffer { GpuEmitter emitters[]; };
layout(std430, binding = 4) readonly buffer LightTreeBuffer { GpuLightNode lightTree[]; };
// The accessors lights.glsl reads through (the renderer's are texel fetches: lib/light_bindings.glsl).
GpuLight lightAt(uint i) { return lights[i]; }
GpuEmitter emitterAt(uint i) { return emitters[i]; }

#include "lib/lights.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.x) return;
  TreeCase c = cases[i];
  uint count = params.y;
  float selection;
  uint chosen = selectLight(c.p.w, c.p.xyz, c.n.xyz, count, selection);
  float asked = lightSelectionPdf(floatBitsToUint(c.n.w), c.p.xyz, c.n.xyz, count);
  float ofChosen = selection > 0.0 ? lightSelectionPdf(chosen, c.p.xyz, c.n.xyz, count) : 0.0;
  results[i] = vec4(uintBitsToFloat(chosen), selection, asked, ofChosen);
}
