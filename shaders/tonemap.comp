#version 460
// tonemap.comp — one composed AOV to display RGBA8: exposure (2^stops), then the sRGB transfer
// curve (IEC 61966-2-1), rounded to 8 bits. What PNG output and the window show [SPEC §5].
// The C++ twin is io::encodeSrgb8 (host/io/image_io.cpp); tests compare the two.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"

layout(local_size_x = kWorkgroupSize1D) in;
layout(push_constant) uniform Push { TonemapPush pc; };
layout(std430, binding = kBindingTonemapInput) readonly buffer In { vec4 composed[]; };
layout(std430, binding = kBindingTonemapOutput) writeonly buffer Out { uint display[]; };

float srgbEncode(float linear) {
  float x = clamp(linear, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

void main() {
  uint pixel = gl_GlobalInvocationID.x;
  if (pixel >= pc.frame.x * pc.frame.y) return;
  vec4 v = composed[pixel * pc.slots.x + pc.frame.z];
  vec3 rgb = pc.frame.w == 1u ? v.xxx : v.rgb;
  // NaN never reaches a display byte: it shows as 0 (the renderer reports non-finite values apart).
  uvec3 bytes;
  for (int c = 0; c < 3; ++c) {
    float x = rgb[c] * pc.params.x;
    bytes[c] = uint(floor(srgbEncode(isnan(x) ? 0.0 : x) * 255.0 + 0.5));
  }
  display[pixel] = bytes.r | (bytes.g << 8u) | (bytes.b << 16u) | (255u << 24u);
}
