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

// The k-th point of the 4-D Kronecker sequence R_4 (Roberts 2018, "The Unreasonable
// Effectiveness of Quasirandom Sequences": alpha_i = phi_4^-i, phi_4^5 = phi_4 + 1), shifted by
// one random `shift` per hit (Cranley-Patterson rotation): each point is uniform, so estimates stay
// unbiased, and the N_s light samples of a hit spread over the lights and over each light instead
// of clumping (measured in docs/BENCHMARKS.md).
vec4 kroneckerPoint4(uint k, vec4 shift) {
  const vec4 kR4 = vec4(0.8566748838545029, 0.7338918566271259, 0.6287067210378087, 0.5385972572236101);
  return min(fract(shift + float(k) * kR4), vec4(0.99999994));
}

vec4 rngNext4(inout uint state) { return vec4(rngNext(state), rngNext(state), rngNext(state), rngNext(state)); }

#endif
