// rng.glsl — per-pixel random numbers: a PCG hash seeds a small PCG32-style stream.
// Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020 (pcg hash).
#ifndef OBSCURA_RNG_GLSL
#define OBSCURA_RNG_GLSL

uint pcgHash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// A stream for (pixel, sample, seed): hashing all three decorrelates neighbouring pixels.
uint rngSeed(uvec2 pixel, uint sampleIndex, uint seed) {
  return pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(sampleIndex ^ pcgHash(seed))));
}

// Uniform float in [0, 1): the top 24 bits, so 1.0 is never returned.
float rngNext(inout uint state) {
  state = state * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  word = (word >> 22u) ^ word;
  return float(word >> 8u) * (1.0 / 16777216.0);
}

#endif
