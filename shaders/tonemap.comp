#version 460
// tonemap.comp — one composed AOV to display RGBA8: exposure (2^stops), then the sRGB transfer
// curve, rounded to 8 bits (lib/srgb.glsl). What PNG output and the window show [SPEC §5].
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/srgb.glsl"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { TonemapPush pc; };
layout(std430, binding = kBindingTonemapInput) readonly buffer In { vec4 composed[]; };
layout(std430, binding = kBindingTonemapOutput) writeonly buffer Out { uint display[]; };

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  if (pixel >= pc.width * pc.rows) return;
  vec4 v = composed[pixel * pc.composedSlots + pc.slot];
  display[pixel] = displayRgba8(pc.channels == 1u ? v.xxx : v.rgb, pc.exposureScale);
}
