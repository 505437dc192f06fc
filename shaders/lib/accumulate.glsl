// accumulate.glsl — compensated (Kahan) summation of progressive samples.
//
// Kahan, "Further remarks on reducing truncation errors", CACM 8(1), 1965. A float sum of n
// samples drifts by up to ~n ulps; here the rounding error of every add is carried in a second
// vec4 and fed back into the next, so 100k iterations stay within ~1 ulp of the exact mean
// (tested by Accumulation.*). An accumulator buffer holds vec4 PAIRS: [2i] the running sum, [2i+1]
// the compensation (the negated low-order part lost so far). Readers take [2i] (OBS_SUM).
// `precise` lives inside kahanStep() only: glslang propagates it backwards through everything a
// precise value depends on, and on the caller's side that would be the whole path-tracing loop
// (it ran out of memory); at a function boundary the propagation stops. Without `precise`, Mesa
// folds (t - sum) - y to 0 and the compensation vanishes (Accumulation.* then fails).
#ifndef OBSCURA_ACCUMULATE_GLSL
#define OBSCURA_ACCUMULATE_GLSL

// GLSL cannot pass a buffer array to a function, hence macros.
#define OBS_SUM(array, index) (array[2u * (index)])
// The same sum read through an RGBA32F texel view of the accumulator buffer (compose, resolve):
// lavapipe loads a texel as one 16-byte vector per lane, an SSBO vec4 as four scalar loads.
#define OBS_SUM_TEXEL(view, index) texelFetch(view, int(2u * (index)))

// One Kahan step: returns the new sum; `compensation` is updated in place.
vec4 kahanStep(vec4 sum, inout vec4 compensation, vec4 value) {
  precise vec4 y = value - compensation;
  precise vec4 t = sum + y;
  precise vec4 c = (t - sum) - y;
  compensation = c;
  return t;
}

// A probing pass (probe.glsl) sums nothing. `value` is then not evaluated: a call with side effects
// (rays, random numbers) goes before the macro.
#ifdef OBSCURA_PROBE_GLSL
#define OBS_SUMS_OFF kProbe
#else
#define OBS_SUMS_OFF false
#endif

#define OBS_ACCUMULATE(array, index, value)                          \
  {                                                                   \
    if (!OBS_SUMS_OFF) {                                              \
      uint k_ = 2u * (index);                                         \
      vec4 c_ = array[k_ + 1u];                                       \
      array[k_] = kahanStep(array[k_], c_, (value));                  \
      array[k_ + 1u] = c_;                                            \
    }                                                                 \
  }

// The same step on an accumulator bound as an RGBA32F storage texel buffer (imageBuffer): lavapipe
// loads and stores a texel as one 16-byte vector per lane, an SSBO vec4 as four scalar accesses.
// An invocation's own earlier store is visible to its later load (program order), as with an SSBO.
#define OBS_ACCUMULATE_TEXEL(image, index, value)                  \
  {                                                                 \
    if (!OBS_SUMS_OFF) {                                            \
      int k_ = int(2u * (index));                                   \
      vec4 c_ = imageLoad(image, k_ + 1);                           \
      imageStore(image, k_, kahanStep(imageLoad(image, k_), c_, (value))); \
      imageStore(image, k_ + 1, c_);                                \
    }                                                               \
  }

// Starts an accumulator at `value` (the first sample: no clear needed).
#define OBS_ACCUMULATE_FIRST(array, index, value)           \
  {                                                          \
    uint k_ = 2u * (index);                                  \
    array[k_] = (value);                                     \
    array[k_ + 1u] = vec4(0.0);                              \
  }

#endif
