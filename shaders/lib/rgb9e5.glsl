// rgb9e5.glsl — RGB in one 32-bit word with a shared exponent (9-bit mantissas, 5-bit exponent,
// bias 15), as GL_EXT_texture_shared_exponent defines it. The relighting path stores the resolved
// per-light transport this way: on lavapipe a per-pixel load costs one scalar load per lane and
// 32-bit word, so one word per light and pixel halves the light-mix pass against half floats.
// Each channel is kept to 2^-9 of the pixel's largest channel; values clamp at 65408.
#ifndef OBSCURA_RGB9E5_GLSL
#define OBSCURA_RGB9E5_GLSL

const float kRgb9e5Max = 65408.0; // (511 / 512) * 2^16

uint packRgb9e5(vec3 rgb) {
  vec3 c = clamp(rgb, vec3(0.0), vec3(kRgb9e5Max)); // NaN clamps to 0 on every GPU we target
  float maxc = max(c.r, max(c.g, c.b));
  int e = max(-16, int(floor(log2(max(maxc, 1e-30))))) + 16; // biased exponent, >= 0
  float denom = exp2(float(e - 15 - 9));
  if (floor(maxc / denom + 0.5) >= 512.0) { // rounding reached the next power of two
    denom *= 2.0;
    e += 1;
  }
  uvec3 m = uvec3(min(floor(c / denom + 0.5), vec3(511.0)));
  return m.r | (m.g << 9u) | (m.b << 18u) | (uint(e) << 27u);
}

vec3 unpackRgb9e5(uint v) {
  // 2^(e - 24) built from its float bits (exponent field e - 24 + 127 >= 103: never denormal).
  float scale = uintBitsToFloat(((v >> 27u) + 103u) << 23u);
  return vec3(float(v & 511u), float((v >> 9u) & 511u), float((v >> 18u) & 511u)) * scale;
}

#endif
