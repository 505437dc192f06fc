// srgb.glsl — the sRGB transfer curve (IEC 61966-2-1) and RGBA8 packing for display bytes. The
// C++ twin is io::linearToSrgb (host/io/image_io.cpp).
#ifndef OBSCURA_SRGB_GLSL
#define OBSCURA_SRGB_GLSL

float srgbEncode(float linear) {
  float x = clamp(linear, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

// Exposed linear rgb to RGBA8 (R in the low byte, alpha 255). NaN shows as 0: the renderer
// reports non-finite values apart, never as a display colour.
uint displayRgba8(vec3 rgb, float exposure) {
  uvec3 bytes;
  for (int c = 0; c < 3; ++c) {
    float x = rgb[c] * exposure;
    bytes[c] = uint(floor(srgbEncode(isnan(x) ? 0.0 : x) * 255.0 + 0.5));
  }
  return bytes.r | (bytes.g << 8u) | (bytes.b << 16u) | (255u << 24u);
}

#endif
